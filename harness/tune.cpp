#include "harness/tune.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "harness/stability.hpp"

namespace cstab {

namespace {

// The method's declared gain (find_gain, as stability maps and stress
// tables find it).
ParamSpec tuned_gain(const Problem& problem, const RunConfig& base) {
  const auto specs = problem.method_params(base.method, base.formulation);
  if (const ParamSpec* g = find_gain(specs)) return *g;
  throw UsageError("--method " + base.method + ": method '" + base.method + "' declares no gain to tune");
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<double> sorted_unique(std::vector<double> v, bool descending) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  if (descending) std::reverse(v.begin(), v.end());
  return v;
}

}  // namespace

double tune_measure(const RunResult& r, const std::string& measure) {
  if (measure == "ref") return r.ref_error;
  if (measure == "residual") return r.max_residual;
  if (measure == "drift") return r.max_energy_drift;
  if (measure == "final") return r.final_residual;
  return std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> default_tune_gains(const ParamSpec& gain) { return tune_gains(gain, 13); }

std::vector<double> tune_gains(const ParamSpec& gain, int n) {
  std::vector<double> out;
  for (int i = 0; i < n; ++i) {
    const double exponent = -1.5 + 3.0 * i / std::max(1, n - 1);
    double g = std::stod(format_3g(gain.default_value * std::pow(10.0, exponent)));  // 3 digits: 47.4, 84.4
    if (gain.bound == Bound::kRange || gain.bound == Bound::kInteger) g = std::clamp(g, gain.lower, gain.upper);
    g = std::min(g, gain.max_value);
    if (param_value_problem(gain, g).empty()) out.push_back(g);
  }
  return sorted_unique(out, false);
}

std::vector<double> default_tune_levels(bool fixed_step) {
  std::vector<double> out;
  if (fixed_step)
    for (int i = 0; i <= 12; ++i) out.push_back(std::stod(format_3g(std::pow(10.0, -1.0 - i / 4.0))));
  else
    for (int i = 0; i <= 8; ++i) out.push_back(std::pow(10.0, -3.0 - i));
  return out;
}

void check_tune(const Problem& problem, const TuneConfig& cfg) {
  const RunConfig& base = cfg.base;
  const IntegratorInfo& integ = find_integrator(base.integrator);
  const ParamSpec gain = tuned_gain(problem, base);
  for (const auto& [name, value] : base.params) {
    const bool tied = std::find(gain.swept_with.begin(), gain.swept_with.end(), name) != gain.swept_with.end();
    if (name == gain.name || tied)
      throw UsageError("--param " + name + "=" + value + ": that is the tuned gain" +
                       (tied ? " (it takes the value of " + gain.name + ")" : "") + "; give --gains instead");
  }
  if (cfg.measure != "ref" && cfg.measure != "residual" && cfg.measure != "drift" && cfg.measure != "final")
    throw UsageError("--measure " + cfg.measure + ": must be ref, residual, drift or final");
  if (!(cfg.target > 0) || !std::isfinite(cfg.target))
    throw UsageError("--target: must be a finite number > 0");
  const ProblemInfo& info = problem.info();
  if (!(base.t_end > 0)) throw UsageError("--t-end: must be > 0");
  if (cfg.measure == "ref") {
    const double t_ref = base.ref_time < 0 ? info.reference_time : base.ref_time;
    if (!(info.reference_time > 0) || !(t_ref > 0) || t_ref > base.t_end)
      throw UsageError("--measure ref: problem '" + info.name + "' has no reference at a time in (0, t_end = " +
                       format_short(base.t_end) + "]");
  }
  if (cfg.measure == "drift" && !info.has_energy)
    throw UsageError("--measure drift: problem '" + info.name + "' has no energy law");
  for (double g : cfg.gains) {
    const std::string why = param_value_problem(gain, g);
    if (!why.empty()) throw UsageError("--gains: " + gain.name + " = " + format_short(g) + " " + why);
  }
  const std::string level_flag = integ.fixed_step ? "--steps" : "--tols";
  for (double l : cfg.levels)
    if (!(l > 0)) throw UsageError(level_flag + ": " + format_short(l) + " must be > 0");
  if (cfg.repeats < 1 || cfg.repeats > 100) throw UsageError("--repeats: must be in [1, 100]");
  if (cfg.cost != "wall" && cfg.cost != "rhs") throw UsageError("--cost " + cfg.cost + ": must be wall or rhs");
  if (!(cfg.prune_ratio == 0 || (cfg.prune_ratio >= 1.2 && std::isfinite(cfg.prune_ratio))))
    throw UsageError("--prune-ratio: must be 0 (no pruning) or a finite number >= 1.2");
  const std::vector<double> gains = cfg.gains.empty() ? default_tune_gains(gain) : cfg.gains;
  const std::vector<double> levels = cfg.levels.empty() ? default_tune_levels(integ.fixed_step) : cfg.levels;
  if (gains.empty()) throw UsageError("--gains: no gain to try");
  const double worst = double(gains.size()) * double(levels.size()) * cfg.repeats;
  if (!(worst <= double(cfg.max_runs)))
    throw UsageError("--gains/" + level_flag + "/--repeats: the search may need " + format_short(worst) +
                     " runs, more than the limit of " + std::to_string(cfg.max_runs) + " (--max-runs raises it)");
  if (integ.fixed_step) {
    const double finest = *std::min_element(levels.begin(), levels.end());
    if (std::ceil(base.t_end / finest) > base.max_steps)
      throw UsageError("--steps: a run at step " + format_short(finest) + " takes " +
                       format_short(std::ceil(base.t_end / finest)) + " steps, more than --max-steps " +
                       format_short(base.max_steps));
  }
  // The method, its other parameters, the problem's and --perturb: one short
  // run, before anything is written (run_case throws UsageError).
  RunConfig probe = base;
  const double coarsest = *std::max_element(levels.begin(), levels.end());
  if (integ.fixed_step) {
    probe.step.step = coarsest;
    probe.t_end = std::min(base.t_end, coarsest);
  } else {
    probe.step.rtol = probe.step.atol = coarsest;
    probe.t_end = base.t_end * 1e-6;
  }
  probe.ref_time = 0;
  probe.write_series = false;
  apply_gain(probe, gain, gains.front());
  run_case(problem, probe, "");
}

TuneResult tune(const Problem& problem, const TuneConfig& cfg) {
  check_tune(problem, cfg);
  const auto start = std::chrono::steady_clock::now();
  TuneResult res;
  res.gain = tuned_gain(problem, cfg.base);
  res.fixed_step = find_integrator(cfg.base.integrator).fixed_step;
  res.gains = sorted_unique(cfg.gains.empty() ? default_tune_gains(res.gain) : cfg.gains, false);
  res.levels = sorted_unique(cfg.levels.empty() ? default_tune_levels(res.fixed_step) : cfg.levels, true);

  const size_t ng = res.gains.size();
  std::vector<bool> done(ng, false);
  std::vector<int> last(ng, -1);  // index in res.runs of the gain's previous run
  for (size_t li = 0; li < res.levels.size(); ++li) {
    const double level = res.levels[li];
    for (size_t gi = 0; gi < ng; ++gi) {
      if (done[gi]) continue;
      if (cfg.prune_ratio > 0 && res.reachable && last[gi] >= 0) {
        const TuneRun& prev = res.runs[last[gi]];
        if (prev.status == "ok") {
          // In RHS evaluations, which wall time follows without its noise.
          const double predicted = double(prev.rhs_evals) * (res.fixed_step ? res.levels[li - 1] / level : 1.0);
          if (predicted > cfg.prune_ratio * double(res.best.rhs_evals)) {
            done[gi] = true;
            continue;
          }
        }
      }
      RunConfig rc = cfg.base;
      if (res.fixed_step)
        rc.step.step = level;
      else
        rc.step.rtol = rc.step.atol = level;
      rc.write_series = false;
      if (cfg.measure != "ref") rc.ref_time = 0;  // no reference error to compute
      apply_gain(rc, res.gain, res.gains[gi]);
      TuneRun tr;
      tr.gain = res.gains[gi];
      tr.level = level;
      const RunResult r = run_case(problem, rc, "");
      tr.status = r.status;
      tr.value = tune_measure(r, cfg.measure);
      tr.reached = r.status == "ok" && std::isfinite(tr.value) && tr.value <= cfg.target;
      tr.rhs_evals = r.rhs_evals;
      std::vector<double> walls{r.wall_seconds};
      // Only a setting that reaches the target competes on cost: it alone
      // is timed again.
      for (int k = 1; tr.reached && k < cfg.repeats; ++k) walls.push_back(run_case(problem, rc, "").wall_seconds);
      res.case_runs += long(walls.size());
      tr.repeats = int(walls.size());
      tr.wall = median(walls);
      tr.cost = cfg.cost == "rhs" ? double(tr.rhs_evals) : tr.wall;
      last[gi] = int(res.runs.size());
      res.runs.push_back(tr);
      if (!tr.reached) continue;
      done[gi] = true;
      if (!res.reachable || tr.cost < res.best.cost || (tr.cost == res.best.cost && tr.value < res.best.value)) {
        res.best = tr;
        res.reachable = true;
      }
    }
  }
  for (double g : res.gains)
    for (const auto& r : res.runs)
      if (r.gain == g && r.reached) res.per_gain.push_back(r);
  if (res.reachable) {
    for (const auto& r : res.per_gain)
      if (r.cost <= 1.2 * res.best.cost) {
        res.flat_min = res.flat_count ? std::min(res.flat_min, r.gain) : r.gain;
        res.flat_max = res.flat_count ? std::max(res.flat_max, r.gain) : r.gain;
        ++res.flat_count;
      }
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return res;
}

}  // namespace cstab

#include "harness/run.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>

#include "io/csv.hpp"
#include "io/number.hpp"
#include "core/format.hpp"

namespace cstab {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Everything recorded along a run, reused at every observation.
class Recorder {
 public:
  Recorder(const Problem& problem, Formulation& form, RunResult& result, AtomicFile* series,
           double sample_every, double fit_from, double t_end)
      : problem_(problem), form_(form), result_(result), series_(series),
        sample_every_(sample_every) {
    // Checkpoints of the running max drift for the growth fit (energy, then
    // each first integral), allocated here, filled during the run.
    if (fit_from > 0 && t_end >= 4 * fit_from) {
      fit_from_ = fit_from;
      fit_ratio_ = std::pow(t_end / fit_from, 1.0 / (kCheckpoints - 1));
      next_checkpoint_ = fit_from;
      const size_t quantities = 1 + problem.info().first_integrals.size();
      checkpoint_t_.reserve(kCheckpoints);
      checkpoint_max_.assign(quantities, {});
      for (auto& v : checkpoint_max_) v.reserve(kCheckpoints);
    }
    const auto& info = problem.info();
    const auto& cons = form.constraints();
    canonical_.assign(info.coordinates.size(), 0);
    residuals_.assign(cons.size(), 0);
    integrals_.assign(info.first_integrals.size(), 0);
    integrals0_.assign(info.first_integrals.size(), 0);
    for (const auto& c : cons) result_.constraints.push_back({c.name, 0, 0});
    result_.has_energy = info.has_energy;
    for (const auto& name : info.first_integrals) result_.max_integral_drift.emplace_back(name, 0.0);
    if (series_) {
      std::string header = "t";
      for (const auto& name : info.coordinates) header += "," + name;
      for (const auto& c : cons) header += ",residual_" + c.name;
      if (info.has_energy) header += ",energy_drift";
      for (const auto& name : info.first_integrals) header += "," + name + "_drift";
      if (form.has_condition_number()) header += ",cond";
      series_->write(header + "\n");
    }
  }

  // Returns false if the state diverged (reason set in result).
  bool observe(double t, const double* y, bool series_row, double blowup) {
    const auto start = Clock::now();
    const bool ok = observe_impl(t, y, series_row, blowup);
    result_.observe_seconds += seconds_since(start);
    return ok;
  }

  bool due_for_sample(double t) const { return series_ && t >= next_sample_; }
  const std::vector<double>& canonical() const { return canonical_; }

 private:
  bool observe_impl(double t, const double* y, bool series_row, double blowup) {
    const int n = form_.dimension();
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(y[i])) {
        result_.status = "diverged";
        result_.reason = "non-finite state";
        result_.fail_time = t;
        return false;
      }
    }
    form_.to_canonical(t, y, canonical_.data());
    form_.residuals(t, y, residuals_.data());
    double max_now = 0;
    for (size_t i = 0; i < residuals_.size(); ++i) {
      const double r = std::abs(residuals_[i]);
      auto& m = result_.constraints[i];
      m.max_abs = std::max(m.max_abs, r);
      m.final_abs = r;
      max_now = std::max(max_now, r);
    }
    result_.final_residual = max_now;
    if (first_) result_.initial_residual = max_now;
    if (!(max_now <= result_.recovery_threshold))
      result_.recovery_time = std::numeric_limits<double>::quiet_NaN();
    else if (std::isnan(result_.recovery_time))
      result_.recovery_time = t;
    result_.max_residual = std::max(result_.max_residual, max_now);
    double energy_drift = 0;
    if (result_.has_energy) {
      const double e = problem_.energy(t, canonical_.data());
      if (first_) energy0_ = e;
      energy_drift = e - energy0_;
      result_.final_energy_drift = std::abs(energy_drift);
      result_.max_energy_drift = first_ ? 0.0 : std::max(result_.max_energy_drift, std::abs(energy_drift));
    }
    if (!integrals_.empty()) {
      problem_.first_integrals(t, canonical_.data(), integrals_.data());
      if (first_) integrals0_ = integrals_;
      for (size_t i = 0; i < integrals_.size(); ++i)
        result_.max_integral_drift[i].second =
            std::max(result_.max_integral_drift[i].second, std::abs(integrals_[i] - integrals0_[i]));
    }
    first_ = false;
    result_.t_reached = t;
    if (fit_from_ > 0 && t >= next_checkpoint_ && checkpoint_t_.size() < kCheckpoints) {
      checkpoint_t_.push_back(t);
      checkpoint_max_[0].push_back(result_.has_energy ? result_.max_energy_drift : 0.0);
      for (size_t i = 0; i < integrals_.size(); ++i) checkpoint_max_[i + 1].push_back(result_.max_integral_drift[i].second);
      while (next_checkpoint_ <= t) next_checkpoint_ *= fit_ratio_;
    }
    if (series_ && (series_row || t >= next_sample_)) {
      if (t >= next_sample_)
        next_sample_ = sample_every_ * (std::floor(t / sample_every_ + 1e-9) + 1);
      line_ = format_exact(t);
      for (double c : canonical_) append(c);
      for (double r : residuals_) append(r);
      if (result_.has_energy) append(energy_drift);
      for (size_t i = 0; i < integrals_.size(); ++i) append(integrals_[i] - integrals0_[i]);
      if (form_.has_condition_number()) {
        const double cond = form_.condition_number(t, y);
        append(cond);
        if (std::isfinite(cond))
          result_.max_condition = std::isnan(result_.max_condition)
                                      ? cond
                                      : std::max(result_.max_condition, cond);
      }
      line_ += '\n';
      series_->write(line_);
    }
    if (!(max_now <= blowup)) {
      result_.status = "diverged";
      result_.reason = std::isfinite(max_now)
                           ? "residual " + format_short(max_now) + " above blow-up threshold " +
                                 format_short(blowup)
                           : "non-finite residual";
      result_.fail_time = t;
      return false;
    }
    return true;
  }

  // Growth exponents from the checkpoints (after the run).
 public:
  void fit_drift_growth() {
    auto slope = [&](const std::vector<double>& m) {
      double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
      for (size_t k = 0; k < checkpoint_t_.size(); ++k) {
        if (!(m[k] > 0) || !std::isfinite(m[k])) continue;
        const double x = std::log(checkpoint_t_[k]), y = std::log(m[k]);
        n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
      }
      const double den = n * sxx - sx * sx;
      return n >= 5 && den > 0 ? (n * sxy - sx * sy) / den : std::numeric_limits<double>::quiet_NaN();
    };
    const bool fitted = !checkpoint_t_.empty();
    if (result_.has_energy && fitted) result_.energy_drift_exponent = slope(checkpoint_max_[0]);
    for (size_t i = 0; i < integrals_.size(); ++i)
      result_.integral_drift_exponent.emplace_back(
          problem_.info().first_integrals[i],
          fitted ? slope(checkpoint_max_[i + 1]) : std::numeric_limits<double>::quiet_NaN());
  }

 private:

  void append(double v) {
    line_ += ',';
    line_ += format_exact(v);
  }

  const Problem& problem_;
  Formulation& form_;
  RunResult& result_;
  AtomicFile* series_;
  double sample_every_;
  double next_sample_ = 0;
  bool first_ = true;
  double energy0_ = 0;
  std::vector<double> canonical_, residuals_, integrals_, integrals0_;
  std::string line_;
  static constexpr size_t kCheckpoints = 40;
  double fit_from_ = 0, fit_ratio_ = 1, next_checkpoint_ = 0;
  std::vector<double> checkpoint_t_;
  std::vector<std::vector<double>> checkpoint_max_;
};

void check_positive_finite(double v, const std::string& flag) {
  if (!std::isfinite(v)) throw UsageError(flag + ": must be a finite number");
  if (!(v > 0)) throw UsageError(flag + ": must be > 0");
}

}  // namespace

void perturb_initial_state(double delta, int n, double* y) {
  for (int i = 0; i < n; ++i) y[i] += delta * std::sin(double(i + 1));
}

double significant_digits(const std::vector<double>& y, const std::vector<double>& ref) {
  double worst = 0;
  for (size_t i = 0; i < y.size() && i < ref.size(); ++i)
    if (!std::isnan(ref[i]))  // a component the reference does not publish
      worst = std::max(worst, std::abs(y[i] - ref[i]) / (1.0 + std::abs(ref[i])));
  if (!std::isfinite(worst)) return 0;
  return worst == 0 ? 17.0 : std::min(17.0, -std::log10(worst));
}

RunResult run_case(const Problem& registered, const RunConfig& cfg, const std::string& out_dir) {
  // ---- validate everything before any file is created ----
  std::string problem_params;
  const std::unique_ptr<Problem> variant = problem_variant(registered, cfg.problem_params, &problem_params);
  const Problem& problem = variant ? *variant : registered;
  const IntegratorInfo& integ_info = find_integrator(cfg.integrator);
  check_positive_finite(cfg.t_end, "--t-end");
  if (!(cfg.max_steps >= 1) || !std::isfinite(cfg.max_steps) || cfg.max_steps > 1e15)
    throw UsageError("--max-steps: must be a number in [1, 1e15]");
  if (integ_info.fixed_step) {
    check_positive_finite(cfg.step.step, "--step");
    if (cfg.step.step > cfg.t_end) throw UsageError("--step: larger than --t-end");
    const double steps = cfg.t_end / cfg.step.step;
    if (!(steps <= cfg.max_steps))
      throw UsageError("--step " + format_short(cfg.step.step) + ": t_end / step = " + format_3g(steps) +
                       " steps, more than the limit of " + format_short(cfg.max_steps) +
                       " (--max-steps raises it)");
  } else {
    check_positive_finite(cfg.step.rtol, "--rtol");
    check_positive_finite(cfg.step.atol, "--atol");
  }
  for (double t : cfg.times) {
    if (!std::isfinite(t) || t <= 0 || t > cfg.t_end)
      throw UsageError("--times: " + format_short(t) + " is outside (0, t_end]");
  }
  if (cfg.sample_every < 0 || !std::isfinite(cfg.sample_every))
    throw UsageError("--sample-every: must be a finite number >= 0");
  if (!(cfg.blowup > 0)) throw UsageError("--blowup: must be > 0");
  if (cfg.observe_every < 1) throw UsageError("--observe-every: must be >= 1");
  if (!std::isfinite(cfg.perturb) || cfg.perturb < 0) throw UsageError("--perturb: must be a finite number >= 0");
  if (!std::isfinite(cfg.drift_fit_from) || cfg.drift_fit_from < 0)
    throw UsageError("--drift-fit-from: must be a finite number >= 0 (0: no fit)");
  if (!(cfg.recovery_threshold > 0)) throw UsageError("--recovery-threshold: must be > 0");
  const std::string why = problem.why_not(cfg.method);
  if (!why.empty()) throw UsageError("--method " + cfg.method + ": " + why);
  const auto specs = problem.method_params(cfg.method, cfg.formulation);
  const Params params = Params::resolve(specs, cfg.params, cfg.method);
  auto form = problem.make(cfg.method, cfg.formulation, params);
  // A DAE formulation (F(t, y, y') = 0) needs a DAE solver, a method that
  // steps itself the "own" integrator, and each of those needs one.
  const MethodKind kind = method_kind_of(*form);
  if (const std::string wrong = pairing_error(kind, cfg.method, integ_info); !wrong.empty()) throw UsageError(wrong);
  if (cfg.perturb > 0 && kind != MethodKind::kOde)
    throw UsageError("--perturb: method '" + cfg.method +
                     "' makes its initial values consistent before it starts (a DAE solver needs them), "
                     "so it cannot start off the manifold");
  if (cfg.perturb > 0 && form->constraints_hold_by_construction())
    throw UsageError("--perturb: the " + form->formulation_name() + " formulation satisfies the constraints by construction; "
                     "there is no manifold to leave");
  auto integrator = make_integrator(cfg.integrator, cfg.step);
  form->set_step_hint(integ_info.fixed_step ? cfg.step.step : 0.0);

  RunResult result;
  result.problem = cfg.problem;
  result.problem_params = problem_params;
  result.formulation = form->formulation_name();
  result.method = cfg.method;
  result.params = params.describe();
  result.integrator = cfg.integrator;
  result.step = cfg.step;
  result.t_end = cfg.t_end;
  result.perturb = cfg.perturb;
  result.recovery_threshold = cfg.recovery_threshold;
  const auto& info = problem.info();
  double ref_time = cfg.ref_time < 0 ? info.reference_time : cfg.ref_time;
  if (ref_time > cfg.t_end || ref_time <= 0) ref_time = 0;
  if (ref_time > 0) {
    result.ref_state.assign(info.coordinates.size(), 0);
    if (!problem.reference(ref_time, result.ref_state.data())) {
      ref_time = 0;
      result.ref_state.clear();
    }
  }
  if (ref_time > 0) result.ref_time = ref_time;

  std::unique_ptr<AtomicFile> series, summary;
  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) throw UsageError("--out " + out_dir + ": cannot create folder: " + ec.message());
    try {
      summary = std::make_unique<AtomicFile>(out_dir + "/summary.csv");
      if (cfg.write_series) series = std::make_unique<AtomicFile>(out_dir + "/series.csv");
    } catch (const std::exception& e) {
      throw UsageError(std::string("--out ") + out_dir + ": " + e.what());
    }
  }

  // ---- integrate ----
  const int n = form->dimension();
  std::vector<double> y0(n), y_out(n);
  form->initial_state(y0.data());
  if (cfg.perturb > 0) perturb_initial_state(cfg.perturb, n, y0.data());
  const double sample_every = cfg.sample_every > 0 ? cfg.sample_every : cfg.t_end / 1000;
  Recorder recorder(problem, *form, result, series.get(), sample_every, cfg.drift_fit_from, cfg.t_end);

  std::vector<double> targets = cfg.times;
  if (ref_time > 0) targets.push_back(ref_time);
  targets.push_back(cfg.t_end);
  std::sort(targets.begin(), targets.end());
  targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  std::vector<double> output_times = cfg.times;  // sorted: a lookup per target stays O(log n)
  std::sort(output_times.begin(), output_times.end());
  auto is_output_time = [&](double t) {
    return t == cfg.t_end || std::binary_search(output_times.begin(), output_times.end(), t);
  };

  const auto start = Clock::now();
  integrator->start(*form, 0.0, y0.data());
  bool alive = recorder.observe(0.0, y0.data(), true, cfg.blowup);
  long since_observed = 0;
  for (double target : targets) {
    if (!alive) break;
    while (alive && integrator->t() < target) {
      if (double(integrator->steps()) >= cfg.max_steps) {
        result.status = "failed";
        result.reason = "step limit: " + format_short(cfg.max_steps) + " steps taken by t = " +
                        format_short(integrator->t()) + " (--max-steps raises it)";
        result.fail_time = integrator->t();
        alive = false;
        break;
      }
      const StepOutcome outcome = integrator->step(target);
      if (outcome == StepOutcome::kPastLimit) break;
      if (outcome == StepOutcome::kFailed) {
        result.status = "failed";
        result.reason = integrator->failure_reason();
        result.fail_time = integrator->t();
        alive = false;
        break;
      }
      if (form->has_post_step() && !integrator->applies_post_step() &&
          form->post_step(integrator->t(), integrator->y())) {
        if (!integrator->notify_modified()) {
          result.status = "failed";
          result.reason = integrator->failure_reason();
          result.fail_time = integrator->t();
          alive = false;
          break;
        }
      }
      // A step that reaches the target is observed just below, once.
      if (integrator->t() < target &&
          (++since_observed >= cfg.observe_every || recorder.due_for_sample(integrator->t()))) {
        since_observed = 0;
        alive = recorder.observe(integrator->t(), integrator->y(), false, cfg.blowup);
      }
    }
    if (!alive) break;
    // The exact state at `target`.
    const double* y_target = integrator->y();
    if (integrator->t() != target) {
      if (!integrator->state_at(target, y_out.data())) {
        result.status = "failed";
        result.reason = integrator->failure_reason().empty() ? "cannot reach output time"
                                                              : integrator->failure_reason();
        result.fail_time = integrator->t();
        break;
      }
      y_target = y_out.data();
    }
    alive = recorder.observe(target, y_target, is_output_time(target), cfg.blowup);
    if (!alive) break;
    if (target == ref_time) {
      result.state_at_ref = recorder.canonical();
      double err = 0;
      for (size_t i = 0; i < result.ref_state.size(); ++i)
        if (!std::isnan(result.ref_state[i])) err = std::max(err, std::abs(result.state_at_ref[i] - result.ref_state[i]));
      result.ref_error = err;
      result.ref_scd = significant_digits(result.state_at_ref, result.ref_state);
    }
    if (target == cfg.t_end) result.final_state = recorder.canonical();
  }
  result.wall_seconds = std::max(0.0, seconds_since(start) - result.observe_seconds);
  if (result.status != "ok") result.recovery_time = std::numeric_limits<double>::quiet_NaN();
  recorder.fit_drift_growth();
  result.steps = integrator->steps();
  result.rejected_steps = integrator->rejected_steps();
  result.rhs_evals = integrator->rhs_evals();
  for (auto& kv : integrator->statistics()) result.extra.push_back(std::move(kv));

  // ---- write ----
  if (!out_dir.empty()) {
    if (series) series->commit();
    summary->write(key_value_csv(result.summary_row()));
    summary->commit();
    // A series.csv of an earlier run into this folder does not belong to this summary.
    if (!series) std::remove((out_dir + "/series.csv").c_str());
  }
  return result;
}

std::vector<std::pair<std::string, std::string>> RunResult::summary_row() const {
  std::vector<std::pair<std::string, std::string>> row;
  // Measured values round-trip exact, "" for none (io/number.hpp); settings in shortest form.
  const auto num = number_cell;
  row.emplace_back("problem", problem);
  row.emplace_back("problem_params", problem_params);
  row.emplace_back("formulation", formulation);
  row.emplace_back("method", method);
  row.emplace_back("params", params);
  row.emplace_back("integrator", integrator);
  row.emplace_back("step", step.step > 0 ? format_short(step.step) : "");
  row.emplace_back("rtol", step.rtol > 0 ? format_short(step.rtol) : "");
  row.emplace_back("atol", step.atol > 0 ? format_short(step.atol) : "");
  row.emplace_back("status", status);
  row.emplace_back("reason", reason);
  row.emplace_back("fail_time", num(fail_time));
  row.emplace_back("t_end", format_short(t_end));
  row.emplace_back("t_reached", format_exact(t_reached));
  row.emplace_back("steps", std::to_string(steps));
  row.emplace_back("rejected_steps", std::to_string(rejected_steps));
  row.emplace_back("rhs_evals", std::to_string(rhs_evals));
  row.emplace_back("wall_seconds", format_exact(wall_seconds));
  row.emplace_back("observe_seconds", format_exact(observe_seconds));
  row.emplace_back("max_residual", format_exact(max_residual));
  row.emplace_back("final_residual", format_exact(final_residual));
  row.emplace_back("max_energy_drift", has_energy ? num(max_energy_drift) : "");
  row.emplace_back("final_energy_drift", has_energy ? num(final_energy_drift) : "");
  row.emplace_back("energy_law", has_energy ? "yes" : "none (skipped)");
  row.emplace_back("max_condition", num(max_condition));
  row.emplace_back("ref_time", num(ref_time));
  row.emplace_back("ref_error", num(ref_error));
  row.emplace_back("ref_scd", num(ref_scd));
  row.emplace_back("perturb", format_short(perturb));
  row.emplace_back("initial_residual", num(initial_residual));
  row.emplace_back("recovery_time", num(recovery_time));
  row.emplace_back("recovered", recovered() ? "yes" : "no");
  row.emplace_back("energy_drift_exponent", has_energy ? num(energy_drift_exponent) : "");
  for (const auto& c : constraints) row.emplace_back("max_residual_" + c.name, format_exact(c.max_abs));
  for (const auto& c : constraints) row.emplace_back("final_residual_" + c.name, format_exact(c.final_abs));
  for (const auto& [name, v] : max_integral_drift) row.emplace_back("max_" + name + "_drift", format_exact(v));
  for (const auto& [name, v] : integral_drift_exponent) row.emplace_back(name + "_drift_exponent", num(v));
  for (const auto& kv : extra) row.push_back(kv);
  return row;
}

}  // namespace cstab

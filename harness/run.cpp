#include "harness/run.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>

#include "io/csv.hpp"
#include "io/number.hpp"
#include "core/format.hpp"
#include "harness/recorder.hpp"

namespace cstab {

namespace {

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

namespace {

// The run's numeric settings (before any formulation is built).
void check_run_settings(const RunConfig& cfg, const IntegratorInfo& integ_info) {
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
}

// The method's formulation on the problem, checked against the integrator
// and the perturbed start.
std::unique_ptr<Formulation> make_checked_formulation(const Problem& problem, const RunConfig& cfg,
                                                      const IntegratorInfo& integ_info, Params* params) {
  const std::string why = problem.why_not(cfg.method);
  if (!why.empty()) throw UsageError("--method " + cfg.method + ": " + why);
  const auto specs = problem.method_params(cfg.method, cfg.formulation);
  *params = Params::resolve(specs, cfg.params, cfg.method);
  auto form = problem.make(cfg.method, cfg.formulation, *params);
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
  return form;
}

// The result's settings, and the reference state where the run reaches the
// reference time (result.ref_time stays 0 otherwise).
void start_result(RunResult& result, const Problem& problem, const RunConfig& cfg, const Formulation& form,
                  const Params& params, const std::string& problem_params) {
  result.problem = cfg.problem;
  result.problem_params = problem_params;
  result.formulation = form.formulation_name();
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
}

void record_failure(RunResult& result, std::string reason, double t) {
  result.status = "failed";
  result.reason = std::move(reason);
  result.fail_time = t;
}

// The stepping loop of one run: from t = 0 through each target time (the
// output times, the reference time, t_end), observing as it goes.
class RunLoop {
 public:
  RunLoop(const RunConfig& cfg, Formulation& form, Integrator& integrator, Recorder& recorder, RunResult& result)
      : cfg_(cfg), form_(form), integ_(integrator), recorder_(recorder), result_(result), y_out_(form.dimension()) {
    targets_ = cfg.times;
    if (result.ref_time > 0) targets_.push_back(result.ref_time);
    targets_.push_back(cfg.t_end);
    std::sort(targets_.begin(), targets_.end());
    targets_.erase(std::unique(targets_.begin(), targets_.end()), targets_.end());
    output_times_ = cfg.times;  // sorted: a lookup per target stays O(log n)
    std::sort(output_times_.begin(), output_times_.end());
  }

  void run(const double* y0) {
    integ_.start(form_, 0.0, y0);
    bool alive = recorder_.observe(0.0, y0, true, cfg_.blowup);
    for (double target : targets_) {
      if (!alive || !advance_to(target)) break;
      alive = observe_target(target);
    }
  }

 private:
  // Steps until t reaches `target` (observing on the way); false if the run
  // ended (failed or diverged).
  bool advance_to(double target) {
    while (integ_.t() < target) {
      if (double(integ_.steps()) >= cfg_.max_steps) {
        record_failure(result_,
                       "step limit: " + format_short(cfg_.max_steps) + " steps taken by t = " +
                           format_short(integ_.t()) + " (--max-steps raises it)",
                       integ_.t());
        return false;
      }
      const StepOutcome outcome = integ_.step(target);
      if (outcome == StepOutcome::kPastLimit) break;
      if (outcome == StepOutcome::kFailed ||
          (form_.has_post_step() && !integ_.applies_post_step() && form_.post_step(integ_.t(), integ_.y()) &&
           !integ_.notify_modified())) {
        record_failure(result_, integ_.failure_reason(), integ_.t());
        return false;
      }
      // A step that reaches the target is observed by observe_target, once.
      if (integ_.t() < target && (++since_observed_ >= cfg_.observe_every || recorder_.due_for_sample(integ_.t()))) {
        since_observed_ = 0;
        if (!recorder_.observe(integ_.t(), integ_.y(), false, cfg_.blowup)) return false;
      }
    }
    return true;
  }

  // The exact state at `target`, observed; the error against the reference
  // there, and the final state. False if the run ended.
  bool observe_target(double target) {
    const double* y_target = integ_.y();
    if (integ_.t() != target) {
      if (!integ_.state_at(target, y_out_.data())) {
        record_failure(result_,
                       integ_.failure_reason().empty() ? "cannot reach output time" : integ_.failure_reason(),
                       integ_.t());
        return false;
      }
      y_target = y_out_.data();
    }
    const bool output = target == cfg_.t_end || std::binary_search(output_times_.begin(), output_times_.end(), target);
    if (!recorder_.observe(target, y_target, output, cfg_.blowup)) return false;
    if (target == result_.ref_time) {
      result_.state_at_ref = recorder_.canonical();
      double err = 0;
      for (size_t i = 0; i < result_.ref_state.size(); ++i)
        if (!std::isnan(result_.ref_state[i]))
          err = std::max(err, std::abs(result_.state_at_ref[i] - result_.ref_state[i]));
      result_.ref_error = err;
      result_.ref_scd = significant_digits(result_.state_at_ref, result_.ref_state);
    }
    if (target == cfg_.t_end) result_.final_state = recorder_.canonical();
    return true;
  }

  const RunConfig& cfg_;
  Formulation& form_;
  Integrator& integ_;
  Recorder& recorder_;
  RunResult& result_;
  std::vector<double> targets_, output_times_, y_out_;
  long since_observed_ = 0;
};

}  // namespace

RunResult run_case(const Problem& registered, const RunConfig& cfg, const std::string& out_dir) {
  // ---- validate everything before any file is created ----
  std::string problem_params;
  const std::unique_ptr<Problem> variant = problem_variant(registered, cfg.problem_params, &problem_params);
  const Problem& problem = variant ? *variant : registered;
  const IntegratorInfo& integ_info = find_integrator(cfg.integrator);
  check_run_settings(cfg, integ_info);
  Params params;
  auto form = make_checked_formulation(problem, cfg, integ_info, &params);
  auto integrator = make_integrator(cfg.integrator, cfg.step);
  form->set_step_hint(integ_info.fixed_step ? cfg.step.step : 0.0);
  RunResult result;
  start_result(result, problem, cfg, *form, params, problem_params);
  RunOutputs outputs(out_dir, cfg.write_series);

  // ---- integrate ----
  const int n = form->dimension();
  std::vector<double> y0(n);
  form->initial_state(y0.data());
  if (cfg.perturb > 0) perturb_initial_state(cfg.perturb, n, y0.data());
  const double sample_every = cfg.sample_every > 0 ? cfg.sample_every : cfg.t_end / 1000;
  Recorder recorder(problem, *form, result, outputs.series(), sample_every, cfg.drift_fit_from, cfg.t_end);
  RunLoop loop(cfg, *form, *integrator, recorder, result);
  const auto start = RunClock::now();
  loop.run(y0.data());
  result.wall_seconds = std::max(0.0, seconds_since(start) - result.observe_seconds);
  if (result.status != "ok") result.recovery_time = std::numeric_limits<double>::quiet_NaN();
  recorder.fit_drift_growth();
  result.steps = integrator->steps();
  result.rejected_steps = integrator->rejected_steps();
  result.rhs_evals = integrator->rhs_evals();
  for (auto& kv : integrator->statistics()) result.extra.push_back(std::move(kv));

  // ---- write ----
  outputs.commit(result);
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
  row.emplace_back("rejected_steps", count_cell(rejected_steps));
  row.emplace_back("rhs_evals", count_cell(rhs_evals));
  row.emplace_back("wall_seconds", num(wall_seconds));
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

// One run: problem x method x integrator over [0, t_end], observed step by
// step. Records per-constraint residuals, energy and first-integral drift,
// error against the problem's reference, counts and wall time, and writes
// summary.csv and series.csv atomically.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "harness/integrator.hpp"
#include "core/problem.hpp"

namespace cstab {

// The default bound on the steps of one run (`--max-steps`, matrix key
// `max_steps`): 1e8, five times the longest run of the shipped matrices
// (the Pesterev wheel, h = 1e-5 over 200 s: 2e7 steps).
inline constexpr double kDefaultMaxSteps = 1e8;

struct RunConfig {
  std::string problem;
  std::vector<std::pair<std::string, std::string>> problem_params;  // name, value text (--problem-param)
  std::string method;
  std::string formulation;  // empty: the method's default for this problem
  std::string integrator;
  std::vector<std::pair<std::string, std::string>> params;  // name, value text
  StepSettings step;
  double t_end = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> times;       // exact output times in (0, t_end]
  double sample_every = 0;         // series decimation; 0: t_end / 1000
  double ref_time = -1;            // < 0: the problem's default (if <= t_end); 0: none
  double blowup = 1e3;             // residual above this: diverged
  int observe_every = 1;           // metrics every N steps (always at outputs)
  bool write_series = true;
  // Inconsistent start (stress tests): move the method's initial state off
  // the constraint manifold by `perturb` (see perturb_initial_state); 0: none.
  double perturb = 0;
  // Residual level a run must return to and stay below to count as recovered.
  double recovery_threshold = 1e-10;
  // Long horizons: the growth exponent of the running max drift is fitted
  // over t in [drift_fit_from, t_end] (when t_end >= 4 drift_fit_from).
  double drift_fit_from = 10;
  // Every run ends: a fixed-step run of more than max_steps steps
  // (t_end / step) is refused before it starts (UsageError); an adaptive run
  // that takes max_steps steps stops there, recorded as `failed`.
  double max_steps = kDefaultMaxSteps;
};

struct ConstraintMetrics {
  std::string name;
  double max_abs = 0;
  double final_abs = 0;
};

struct RunResult {
  std::string problem, formulation, method, params, integrator;
  std::string problem_params;  // every problem parameter, "a=1;b=2" ("" for a problem without any)
  std::string status = "ok";  // ok | diverged | failed
  std::string reason;
  double fail_time = std::numeric_limits<double>::quiet_NaN();
  double t_end = 0, t_reached = 0;
  StepSettings step;
  long steps = 0, rejected_steps = 0, rhs_evals = 0;  // -1: not recorded (a scored trajectory)
  double wall_seconds = 0;     // integration alone (observation excluded); NaN: not known
  double observe_seconds = 0;  // time spent in observers
  std::vector<ConstraintMetrics> constraints;
  double max_residual = 0, final_residual = 0;
  bool has_energy = false;
  double max_energy_drift = std::numeric_limits<double>::quiet_NaN();
  double final_energy_drift = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::pair<std::string, double>> max_integral_drift;
  double max_condition = std::numeric_limits<double>::quiet_NaN();
  double ref_time = std::numeric_limits<double>::quiet_NaN();
  double ref_error = std::numeric_limits<double>::quiet_NaN();  // max abs over coordinates
  double ref_scd = std::numeric_limits<double>::quiet_NaN();    // significant correct digits
  std::vector<double> ref_state, state_at_ref;                  // canonical
  std::vector<double> final_state;                              // canonical, at t_reached
  std::vector<std::pair<std::string, std::string>> extra;       // method-specific counters
  // Recovery from an inconsistent start: the largest residual at t = 0, and
  // the first observed time after which every observed residual stayed at
  // or below the threshold (NaN: the last observation was above it).
  double perturb = 0, recovery_threshold = 1e-10;
  double initial_residual = std::numeric_limits<double>::quiet_NaN();
  double recovery_time = std::numeric_limits<double>::quiet_NaN();
  bool recovered() const { return status == "ok" && !std::isnan(recovery_time); }
  // Slope p of log(max_{s<=t} |drift(s)|) against log(t), least squares over
  // log-spaced t in [drift_fit_from, t_reached]: ~0 bounded, ~1/2 random
  // walk, ~1 linear growth. NaN where not fitted.
  double energy_drift_exponent = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::pair<std::string, double>> integral_drift_exponent;

  std::vector<std::pair<std::string, std::string>> summary_row() const;
};

// Validates everything (throws UsageError) before touching the filesystem.
// With out_dir empty nothing is written. `problem` is the registered problem;
// config.problem_params, when given, run a variant of it (problem_variant).
RunResult run_case(const Problem& problem, const RunConfig& config, const std::string& out_dir);

// The deterministic inconsistent start: y_i += delta * sin(i + 1) for every
// component i of the method's state vector (a fixed pattern with no
// sign structure, so no constraint sees the shifts cancel). Mechanical
// methods share the state [q; v], so they all start from the same perturbed
// point; the wheel's state-space form applies the same rule to its own
// state. The constraint violation this produces is recorded as
// initial_residual (about delta times the Jacobian's scale).
void perturb_initial_state(double delta, int n, double* y);

// Significant correct digits of `y` against `ref` (IVP Test Set mescd with
// atol/rtol = 1): min over components of -log10(|y-ref| / (1 + |ref|)).
double significant_digits(const std::vector<double>& y, const std::vector<double>& ref);

}  // namespace cstab

// Linear stability of the fixed-step integrators and measured stability
// boundaries of stabilized runs (issue: replace "lambda about 1/h" folklore
// with maps).
#pragma once

#include <string>
#include <vector>

#include "core/problem.hpp"
#include "harness/run.hpp"

namespace cstab {

// The left end -x of the real stability interval [-x, 0] of a fixed-step
// integrator applied to y' = mu y, computed from its stability polynomial:
// one-step methods from |R(z)| <= 1, the Adams PECE pair from the roots of
// its characteristic polynomial. 0 if the integrator is not fixed-step.
double real_stability_boundary(const std::string& integrator);

struct StabilityPoint {
  double step = 0;
  double gain = 0;       // the parameter value given
  double rate = 0;       // the decay rate it implies (gain, or 1/gain for dt); NaN if not a gain
  std::string status;    // ok | diverged | failed
  double max_residual = 0;
  double final_residual = 0;
  double fail_time = 0;  // NaN if it did not blow up
};

struct StabilityConfig {
  RunConfig base;              // problem, method, integrator, t_end, other params
  std::string gain_param;      // empty: the method's declared gain (ParamSpec::role)
  std::vector<double> steps;
  std::vector<double> gains;   // grid values
  int bisection_iterations = 10;  // boundary search per step size
};

// The boundary in h * rate, per step of the map: when the swept parameter is
// a gain (a rate or a time scale) and the integrator has a finite real
// stability interval (boundary_in_rate).
struct StabilityBoundary {
  double step = 0;
  double stable_rate = 0;    // largest rate found stable
  double unstable_rate = 0;  // smallest rate found unstable
  double measured = 0;       // h * rate at the boundary (geometric mid)
  double theory = 0;         // real_stability_boundary(integrator)
};

// The boundary in the step, per parameter value of the map: when the swept
// parameter is not a gain (generalized-alpha's rho_inf, HHT's alpha) or the
// integrator has no finite real stability interval (a method's own implicit
// scheme). Between the largest stable step of the grid below its first
// unstable one and that step, bisected in log h; NaN where the grid has no
// such step (every step stable: unstable_step NaN; none: stable_step NaN).
struct StepBoundary {
  double gain = 0;
  double stable_step = 0;    // largest step found stable
  double unstable_step = 0;  // smallest step found unstable
};

// The gain a stability map sweeps: cfg.gain_param, or the method's declared
// gain (find_gain) when that is empty. Throws UsageError if there is none.
ParamSpec gain_spec(const Problem& problem, const StabilityConfig& cfg);
// Sets the gain `spec` to `gain` in `rc.params`, and every parameter swept
// with it (spec.swept_with, e.g. Baumgarte's beta with alpha) to the same value.
void apply_gain(RunConfig& rc, const ParamSpec& spec, double gain);

// Whether the boundary is sought in h * rate (stability_boundaries) or in the
// step (step_boundaries).
bool boundary_in_rate(const ParamSpec& spec, const std::string& integrator);

std::vector<StabilityPoint> stability_map(const Problem& problem, const StabilityConfig& config);
std::vector<StabilityBoundary> stability_boundaries(const Problem& problem, const StabilityConfig& config);
// `map` is stability_map's result for `config`.
std::vector<StepBoundary> step_boundaries(const Problem& problem, const StabilityConfig& config,
                                          const std::vector<StabilityPoint>& map);

}  // namespace cstab

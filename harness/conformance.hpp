// How the conformance checks run a method on a problem (the GoogleTest
// suite tests/conformance/ and `cstab check`): the settings the method
// declares (ConformanceSettings, core/problem.hpp) within the problem's
// resolution step, and the derivative check of a model through `none`.
#pragma once

#include <string>

#include "harness/run.hpp"

namespace cstab {

// The run of `method` on `problem` to t_end with the method's declared
// integrator, step or tolerance and parameters; `accuracy`: the run's
// accuracy is checked (a consistent start), so the method's accuracy_steps
// apply. Throws std::logic_error if the settings name a time-scale gain the
// method does not declare.
RunConfig conformance_config(const Problem& problem, const MethodInfo& method, double t_end, bool accuracy);

// The conformance run of `method` on `problem` over [0, min(2, the
// problem's horizon)]: whether the problem's own start is consistent (asked
// of `none` where it applies, since DAE methods move an inconsistent start
// onto the manifold first), then the run with accuracy settings if it is.
struct ConformanceRun {
  double t_end = 0;
  double start_residual = 0;  // largest |residual| at t = 0
  bool consistent_start = false;
  RunConfig config;
  RunResult result;
};
ConformanceRun run_conformance(const Problem& problem, const MethodInfo& method);

// The largest |residual| of the method's formulation at its initial state.
double initial_residual(const Problem& problem, const RunConfig& config);

// The model's derivative chain against its constraint functions, through
// the index-1 formulation of `none` (which makes Phi'' = 0 on holonomic
// rows and Psi' = 0 on the others with the model's Jacobians and gamma, AD
// or closed forms): along the flow y(s) = y + s f + s^2/2 f', the residual's
// second (holonomic) or first (other rows) central difference, relative to
// 1 + |f| + |f'|, at the initial state and at a perturbed one. Returns the
// worst; `detail` says where. NaN (and why in detail) if `none` does not apply.
double derivative_consistency(const Problem& problem, std::string* detail);

}  // namespace cstab

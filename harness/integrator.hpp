// Time-stepping schemes. An integrator advances an OdeSystem one step at a
// time so the harness can observe, project and detect divergence between
// steps. Fixed-step schemes stay on the grid t0 + k h; a state between grid
// points (an exact output time, t_end) is computed by a side step that does
// not disturb the trajectory. Adaptive schemes land exactly on the limit.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/formulation.hpp"
#include "core/problem.hpp"

namespace cstab {

struct IntegratorInfo {
  std::string name;
  std::string description;
  bool fixed_step;  // needs --step; otherwise needs --rtol/--atol
  int order;        // classical order of accuracy
  // Which methods it runs: ODE right-hand sides, DAEs F(t, y, y') = 0 (a
  // DaeSystem), or methods that step themselves (a SteppingSystem).
  MethodKind kind = MethodKind::kOde;
};

const std::vector<IntegratorInfo>& all_integrators();
const IntegratorInfo& find_integrator(const std::string& name);  // throws UsageError

struct StepSettings {
  double step = 0;  // fixed-step schemes
  double rtol = 0;  // adaptive schemes
  double atol = 0;
};

enum class StepOutcome {
  kOk,          // advanced; t() and y() are the new state
  kPastLimit,   // fixed-step: the next grid point lies beyond the limit
  kFailed,      // see failure_reason()
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual void start(OdeSystem& sys, double t0, const double* y0) = 0;
  // One step, never beyond t_limit.
  virtual StepOutcome step(double t_limit) = 0;
  // State at t_target in [t(), next grid point); only for fixed-step schemes.
  virtual bool state_at(double t_target, double* out) = 0;
  // After the caller changed y() in place (projection): refresh any history.
  virtual bool notify_modified() = 0;
  // True if the integrator applies the formulation's post-step hook itself,
  // inside each step (cvode-projection: CVODE's projection interface keeps
  // the projected state in its history); the caller then must not.
  virtual bool applies_post_step() const { return false; }

  double t() const { return t_; }
  double* y() { return y_.data(); }
  const double* y() const { return y_.data(); }
  long steps() const { return steps_; }
  long rejected_steps() const { return rejected_; }
  long rhs_evals() const { return rhs_evals_; }
  double last_step_size() const { return h_used_; }
  const std::string& failure_reason() const { return failure_; }
  // Solver-specific counters (name, value), appended to the summary row.
  virtual std::vector<std::pair<std::string, std::string>> statistics() const { return {}; }

 protected:
  // Counts and forwards to the system; records a failure reason.
  bool eval(double t, const double* y, double* dydt);

  OdeSystem* sys_ = nullptr;
  int n_ = 0;
  double t_ = 0;
  double h_used_ = 0;
  std::vector<double> y_;
  long steps_ = 0, rejected_ = 0, rhs_evals_ = 0;
  std::string failure_;
};

// The kind of method a formulation is (what it derives from).
MethodKind method_kind_of(const Formulation& form);
// "" if an integrator of `integrator` kind runs a method of `method` kind;
// otherwise why not, in words (for a UsageError / a matrix note).
std::string pairing_error(MethodKind method, const std::string& method_name, const IntegratorInfo& integrator);

std::unique_ptr<Integrator> make_integrator(const std::string& name, const StepSettings& settings);

}  // namespace cstab

// A problem as the harness and the CLI see it: its description, canonical
// coordinates, first integrals, reference solution, and a factory that turns
// a method name into a runnable Formulation. Concrete problems are plain
// classes in problems/; methods/problem_adapter.hpp adapts them to this interface.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/formulation.hpp"
#include "core/params.hpp"

namespace cstab {

struct FormulationInfo {
  std::string name;
  std::string description;
  std::vector<ConstraintInfo> constraints;
};

struct ProblemInfo {
  std::string name;
  std::string description;
  std::vector<std::string> coordinates;      // canonical coordinate names
  std::vector<FormulationInfo> formulations;
  bool has_energy = false;
  std::vector<std::string> first_integrals;  // besides energy
  double default_t_end = 10;
  double reference_time = 0;                 // 0: no reference
  std::string reference_description;
  // Largest fixed step that resolves the motion (0: no limit below the
  // method's own setting); fast motions (wheel-sharp's contact point) need less.
  double resolution_step = 0;
};

// How the shared conformance suite (tests/conformance/) runs a method: its
// natural integrator and settings, and what it promises there. Declared by
// the method (static ConformanceSettings conformance()); these are the defaults.
struct ConformanceSettings {
  std::string integrator = "rk8pd";
  double tol = 1e-10;   // adaptive integrators: rtol = atol
  double step = 1e-3;   // fixed-step integrators (at most the problem's resolution_step)
  // > 0: at least this many fixed steps over the horizon where the suite
  // checks accuracy (a consistent start: energy drift and the reference);
  // from an inconsistent start only the residuals are checked, at `step`.
  double accuracy_steps = 0;
  std::vector<std::pair<std::string, std::string>> params = {};
  double time_scale_steps = 0;  // > 0: the method's time-scale gain is this many steps
  bool stabilizes = true;       // false: residuals drift by design (none)
  double residual_bound = 1e-6; // max |residual| from a consistent start; final |residual| from any
  double drift_bound = 1e-4;    // max |residual| allowed to a method that does not stabilize
};

// What a method hands the integrator, and so which integrators run it.
enum class MethodKind {
  kOde,           // y' = f(t, y): the ODE integrators
  kDae,           // F(t, y, y') = 0 (a DaeSystem): "ida"
  kSelfStepping,  // its own implicit scheme (a SteppingSystem): "own"
};

struct MethodInfo {
  std::string name;
  std::string description;
  std::vector<ParamSpec> params;
  MethodKind kind = MethodKind::kOde;  // runs only on integrators of the same kind
  ConformanceSettings conformance = {};
};

class Problem {
 public:
  virtual ~Problem() = default;
  virtual const ProblemInfo& info() const = 0;

  // Parameters `method` takes on this problem, or throws UsageError naming
  // why the method does not apply here.
  virtual std::vector<ParamSpec> method_params(const std::string& method,
                                               const std::string& formulation) const = 0;
  virtual std::unique_ptr<Formulation> make(const std::string& method,
                                            const std::string& formulation,
                                            const Params& params) const = 0;
  // Empty if `method` applies; otherwise the reason it does not.
  virtual std::string why_not(const std::string& method) const = 0;

  // The bare dynamics with every constraint ignored (M^-1 Q for a mechanical
  // model, the drift F for an affine one): the cost baseline of benchmarks.
  // nullptr if the problem has neither.
  virtual std::unique_ptr<Formulation> make_unconstrained() const { return nullptr; }

  // A formulation whose state is exactly the canonical coordinates (its
  // to_canonical is the identity), for scoring a trajectory computed
  // elsewhere (`cstab score`): its residuals() evaluate the constraints at
  // a canonical state. nullptr if no formulation of the problem has the
  // canonical coordinates as its state.
  virtual std::unique_ptr<Formulation> make_observer() const { return nullptr; }

  // Energy of a canonical state (only if info().has_energy).
  virtual double energy(double /*t*/, const double* /*canonical*/) const { return 0; }
  // First integrals other than energy, in info().first_integrals order.
  virtual void first_integrals(double /*t*/, const double* /*canonical*/, double* /*out*/) const {}
  // Canonical state of the reference solution at time t; false if none.
  virtual bool reference(double /*t*/, double* /*canonical*/) const { return false; }

  // The problem's own parameters (a length, a size N), each with its
  // default and range, like a method's; empty: it has none.
  virtual std::vector<ParamSpec> problem_params() const { return {}; }
  // This problem with other parameter values (resolved against problem_params()).
  virtual std::unique_ptr<Problem> with_params(const Params& /*params*/) const { return nullptr; }
};

// The problem a run uses: `base` with the `--problem-param` values `given`
// (validated against base.problem_params(); UsageError naming the parameter
// and its range). `values` receives every parameter's value ("a=1;b=2",
// defaults included; "" for a problem without parameters). Returns nullptr
// when nothing is given: `base` itself is the problem.
std::unique_ptr<Problem> problem_variant(const Problem& base,
                                         const std::vector<std::pair<std::string, std::string>>& given,
                                         std::string* values = nullptr);


}  // namespace cstab

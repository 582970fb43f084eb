// What a method hands to the harness: a first-order system an integrator can
// step, plus the observables the harness records (residuals per constraint,
// the problem's canonical coordinates). Integrators see only OdeSystem.
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace cstab {

// y' = f(t, y) on raw arrays of `dimension()` doubles. Implementations keep
// all workspaces as members, so rhs() never allocates.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int dimension() const = 0;
  // Returns false if the right-hand side cannot be evaluated (singular
  // reaction matrix, non-finite input); failure_reason() then says why.
  virtual bool rhs(double t, const double* y, double* dydt) = 0;
  virtual const std::string& failure_reason() const { return no_failure_; }
  // df/dy at (t, y), dense and column-major (J[i + j n] = df_i/dy_j), for
  // the implicit integrators. A system that gives one says so with
  // has_jacobian(); jacobian() may still return false at a point where it
  // has none (e.g. redundant constraint rows), and the integrator then
  // takes difference quotients there. Must not allocate.
  virtual bool has_jacobian() const { return false; }
  virtual bool jacobian(double /*t*/, const double* /*y*/, double* /*J*/) { return false; }

 private:
  std::string no_failure_;
};

// F(t, y, y') = 0 on raw arrays of `dae_dimension()` doubles, for an
// implicit DAE solver (the "ida" integrator). A Formulation that is a DAE
// derives from both Formulation and DaeSystem: its dimension() equals
// dae_dimension() and its first entries are the mechanical state, so the
// observables (residuals, to_canonical) read the same array; its rhs()
// fails, saying it needs --integrator ida. The reason for a failed
// residual() is OdeSystem::failure_reason().
class DaeSystem {
 public:
  virtual ~DaeSystem() = default;
  virtual int dae_dimension() const = 0;
  // Initial guesses at t0: y as Formulation::initial_state, and y'. The
  // solver makes them consistent (algebraic y and differential y' adjusted).
  virtual void initial_values(double t0, double* y, double* yp) const = 0;
  // Per component: 1 differential (y' appears), 0 algebraic.
  virtual void component_ids(double* id) const = 0;
  // Differentiation index. The solver's consistent-initial-value
  // calculation (IDACalcIC) is for index 1; a higher-index DAE must return
  // consistent initial_values itself (the solver checks F = 0 there).
  virtual int index() const { return 1; }
  // The half-bandwidth of the iteration matrix dF/dy + c dF/dy' when the
  // unknowns are ordered so that it is banded (the runtime-size models of
  // methods/scalable.hpp): IDA then factors a band matrix, O(n) where the
  // dense one is O(n^3). -1: dense.
  virtual int half_bandwidth() const { return -1; }
  // r = F(t, y, y'). Returns false if F cannot be evaluated at this point.
  virtual bool residual(double t, const double* y, const double* yp, double* r) = 0;
};

// A method that is its own time-stepping scheme (the generalized-alpha
// family): an implicit step with a Newton iteration of its own, not a
// right-hand side. It runs only on the "own" integrator, which calls
// advance() on the fixed grid t0 + k h. Like a DaeSystem, a Formulation that
// steps itself derives from both; its state is [q; v; ...extra] (extra: the
// scheme's accelerations and multipliers), so the observables read the same
// array, and its rhs() fails, saying it needs --integrator own.
// Formulation::initial_state gives a complete starting state (the scheme's
// accelerations included).
class SteppingSystem {
 public:
  virtual ~SteppingSystem() = default;
  // y (dimension() doubles) from t to t + h, in place. Returns false if the
  // step failed (OdeSystem::failure_reason() says why); y is then unspecified.
  // Must not allocate.
  virtual bool advance(double t, double h, double* y) = 0;
  // Evaluations of the model's residuals with their Jacobians (for rhs_evals).
  virtual long evaluations() const = 0;
  // Scheme-specific counters (name, value), appended to the summary row.
  virtual std::vector<std::pair<std::string, std::string>> statistics() const { return {}; }
};

struct ConstraintInfo {
  std::string name;  // used in column names: residual_<name>
  std::string kind;  // holonomic | non-holonomic | holonomic (time-dependent) | ...
  std::string description;
};

class Formulation : public OdeSystem {
 public:
  // Short name of the form the problem is written in ("state-space",
  // "mechanical", "minimal"), reported in the summary's `formulation` column.
  virtual std::string formulation_name() const = 0;
  virtual void initial_state(double* y) const = 0;
  // Told the integrator's fixed step before the run (0 for adaptive
  // schemes); a formulation whose parameters depend on it may throw
  // UsageError here for an impossible combination.
  virtual void set_step_hint(double /*fixed_step*/) {}
  // Post-step hook (projection methods). Returns true if it changed y.
  virtual bool has_post_step() const { return false; }
  virtual bool post_step(double /*t*/, double* /*y*/) { return false; }

  // True where the constraints hold by construction (minimal coordinates):
  // there is no manifold to leave, so a perturbed start means nothing.
  virtual bool constraints_hold_by_construction() const { return false; }

  // Observables.
  virtual const std::vector<ConstraintInfo>& constraints() const = 0;
  virtual void residuals(double t, const double* y, double* out) const = 0;
  // Maps the state to the problem's canonical coordinates (series columns).
  virtual void to_canonical(double t, const double* y, double* canonical) const = 0;
  // Condition number of the matrix the method solves for the reactions, if any.
  virtual bool has_condition_number() const { return false; }
  virtual double condition_number(double /*t*/, const double* /*y*/) { return std::nan(""); }
};

}  // namespace cstab

// Mechanical models as DAEs F(t, y, y') = 0 for the "ida" integrator
// (SUNDIALS IDA, BDF). Two classical formulations, both with the constraint
// forces A^T lambda of the mechanical description (methods/mechanical.hpp):
//
//  ida-index1   y = [q; v; lambda]                  (2 nq + nc unknowns)
//      q' - v                      = 0
//      M v' - Q - A^T lambda       = 0
//      A v' + gamma                = 0   acceleration-level constraints
//    lambda algebraic. Index 1: nothing holds Phi = 0 or the velocity
//    constraints, so they drift like the `none` ODE (at the tolerance).
//
//  ida-ggl      y = [q; v; lambda; mu]              (2 nq + nc + nh unknowns)
//      q' - v - J^T mu             = 0   J = dPhi/dq (holonomic rows only)
//      M v' - Q - A^T lambda       = 0
//      [J v + Phi_t; Psi]          = 0   velocity-level constraints
//      Phi                         = 0   position-level constraints
//    lambda, mu algebraic. The stabilized index-2 formulation of
//    Gear, Gupta and Leimkuhler (1985), as in the SUNDIALS example
//    idasSlCrank_dns: mu = 0 on the exact solution and both constraint
//    levels hold to the Newton tolerance. Index-2 variables cannot be
//    error-controlled by BDF, so the integrator excludes algebraic
//    components from the error test (IDASetSuppressAlg), as is standard.
//
// The first 2 nq entries of y are [q; v], so the shared observables
// (residuals, to_canonical) read the same array. Both start from q(0), v(0)
// projected onto the constraints when the problem's data violate them, and
// both need full-rank constraint rows (the iteration matrix contains the
// KKT matrix).
#pragma once

#include <cmath>

#include "methods/consistent_start.hpp"
#include "methods/mechanical_method.hpp"

namespace cstab {

template <class Model, bool kGgl>
class MechanicalDaeFormulation final : public MechanicalFormulationBase<Model>, public DaeSystem {
  using Base = MechanicalFormulationBase<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);
  static constexpr int nm = kGgl ? nh : 0;  // GGL multipliers of q' = v + J^T mu
  static constexpr int kDim = 2 * nq + nc + nm;
  static constexpr int kLambda = 2 * nq;    // offset of lambda in y
  static constexpr int kMu = 2 * nq + nc;   // offset of mu in y
  static constexpr int nk = nq + nc;        // KKT size (initial values)

  MechanicalDaeFormulation(const Model& model, const char* method) : Base(model), method_(method) {}

  int dimension() const override { return kDim; }
  int dae_dimension() const override { return kDim; }

  bool rhs(double, const double*, double*) override {
    this->failure_ = std::string(method_) + " is a DAE formulation: it needs --integrator ida";
    return false;
  }

  void initial_state(double* y) const override {
    Vec<double, kDim> yp;
    initial_values(0.0, y, yp.data());
  }

  // q, v from the model (made consistent, ConsistentStart::state); a and
  // lambda from the KKT system (the acceleration level, exact for consistent
  // q, v); mu = 0, lambda' = mu' = 0.
  void initial_values(double t0, double* y, double* yp) const override {
    VecQ q, v;
    ConsistentStart<Model>::state(this->model_, t0, q, v);
    Vec<double, nk> x;
    ConsistentStart<Model>::accelerations(this->model_, t0, q, v, x);
    for (int i = 0; i < kDim; ++i) y[i] = yp[i] = 0;
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
    vmap<nq>(yp) = v;
    vmap<nq>(yp + nq) = x.template head<nq>();
    if constexpr (nc > 0) vmap<nc>(y + kLambda) = x.template tail<nc>();
  }

  // GGL is index 2: the integrator checks its initial values instead of
  // calling IDACalcIC (index 1 only).
  int index() const override { return kGgl ? 2 : 1; }

  void component_ids(double* id) const override {
    for (int i = 0; i < kDim; ++i) id[i] = i < 2 * nq ? 1.0 : 0.0;
  }

  bool residual(double t, const double* y, const double* yp, double* r) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    const auto qp = vmap<nq>(yp);
    const auto vp = vmap<nq>(yp + nq);
    if constexpr (kGgl) {
      // Velocity and position levels only: no acceleration-level terms.
      this->model_.mass(t, q, terms_.M);
      this->model_.forces(t, q, v, terms_.Q);
      terms_.evaluate_velocity(this->model_, t, q, v);
    } else {
      terms_.evaluate(this->model_, t, q, v, false);
    }
    auto r_q = vmap<nq>(r);
    auto r_v = vmap<nq>(r + nq);
    r_q = qp - v;
    r_v = terms_.M * vp - terms_.Q;
    if constexpr (nc > 0) {
      r_v -= terms_.A.transpose() * vmap<nc>(y + kLambda);
      if constexpr (kGgl)
        vmap<nc>(r + kLambda) = terms_.velocity;
      else
        vmap<nc>(r + kLambda) = terms_.A * vp + terms_.gamma;
    }
    if constexpr (nm > 0) {
      r_q -= terms_.A.template topRows<nh>().transpose() * vmap<nm>(y + kMu);
      vmap<nm>(r + kMu) = terms_.phi;
    }
    for (int i = 0; i < kDim; ++i) {
      if (!std::isfinite(r[i])) {
        this->failure_ = std::string(method_) + ": non-finite residual at t = " + std::to_string(t);
        return false;
      }
    }
    return true;
  }

 private:
  const char* method_;
  MechanicalTerms<Model> terms_;
};

// What the two DAE methods share: for --integrator ida, full rank, no
// parameters; kGgl picks the formulation (index 1 or stabilized index 2).
template <class Derived, bool kGgl>
struct IdaMethod : MechanicalMethod<Derived> {
  static constexpr bool kIsDae = true;  // F(t, y, y') = 0: needs a DAE integrator
  static constexpr bool kNeedsFullRank = true;  // redundant rows: does not apply, naming the rank
  static ConformanceSettings conformance() { return {.integrator = "ida", .tol = 1e-9}; }
  static std::vector<ParamSpec> generic_params() { return {}; }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params&) {
    return std::make_unique<MechanicalDaeFormulation<Model, kGgl>>(model, Derived::kName);
  }
};

struct IdaIndexOneMethod : IdaMethod<IdaIndexOneMethod, false> {
  static constexpr const char* kName = "ida-index1";
  static constexpr const char* kDescription =
      "DAE for --integrator ida: [q, v, lambda], constraints at acceleration level (index 1); drifts at "
      "the tolerance (full rank)";
};

struct IdaGglMethod : IdaMethod<IdaGglMethod, true> {
  static constexpr const char* kName = "ida-ggl";
  static constexpr const char* kDescription =
      "DAE for --integrator ida: stabilized index-2 Gear-Gupta-Leimkuhler [q, v, lambda, mu], position and "
      "velocity constraints enforced (full rank)";
  // Also on the runtime-size path (methods/scalable.hpp): the same DAE with
  // its unknowns interleaved, a band matrix for IDA where the forces are local.
  static ScalableSettings scalable_settings(const Params&) {
    return {.stabilization = ScalableSettings::Stabilization::kGgl};
  }
};

}  // namespace cstab

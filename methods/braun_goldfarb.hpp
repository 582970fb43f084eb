// Braun-Goldfarb explicit equation of constrained motion (Part II, eqs. 1-2):
//   q' = v + R^-1 C_q^+ (b_q - A_q v - Phi_q / dt)
//   v' = a + R^-1 C_v^+ (b_v - A_v a - (Phi_q'; Phi_v) / dt)
//          + R^-1 N_v (C_e N_v)^+ (b_ev - A_ev a - Phi_ev / dt)
// with M = R^T R, a = M^-1 Q, C_* = A_* R^-1, N_v = I - C_v^+ C_v and
// (*)_ev = (*)_e - C_e C_v^+ (*)_v. Here A_q = J, b_q = -Phi_t (so
// b_q - A_q v = -Phi_q'), A_v = [J; G], b_v = -gamma (acceleration-level
// rows A a + gamma), A_e = dE/dv, b_e = -(dE/dt at a = 0), Phi_e = E - E(0).
// (C_e N_v)^+ = (C_e N_v)^T / |C_e N_v|^2 if |C_e N_v|^2 > tol, else 0
// (their footnote 4: tol = 1e-6).
//
// Explicit Euler applied to (1)-(2) with step dt is exactly their
// discretization (3)-(4): `--integrator euler` with dt = 0 (= the step).
#pragma once

#include "methods/mechanical_method.hpp"
#include "linalg/weighted_pinv.hpp"

namespace cstab {

template <class Model>
class BraunGoldfarbFormulation final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);

  BraunGoldfarbFormulation(const Model& model, double dt, bool energy, double tol)
      : Base(model), dt_(dt), energy_(energy), tol_(tol) {
    if constexpr (Model::kHasEnergy) {
      if (energy_) {
        VecQ q, v;
        model.initial_state(q, v);
        energy0_ = model.energy(0.0, q, v);
      }
    }
  }

  void set_step_hint(double fixed_step) override {
    if (dt_ == 0) {
      if (!(fixed_step > 0))
        throw UsageError("--param dt=0 (use the integrator's step) needs a fixed-step integrator; "
                         "give --param dt=<seconds> for adaptive integrators");
      dt_ = fixed_step;
    }
  }

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, energy_);
    if (!mass_.factor(terms_.M)) {
      this->failure_ = "mass matrix not positive definite at t = " + std::to_string(t);
      return false;
    }
    const double inv_dt = 1.0 / dt_;
    const VecQ a = mass_.solve(terms_.Q);
    VecQ qdot = v;
    VecQ vdot = a;
    if constexpr (nh > 0) {
      pinv_q_.set_rows(mass_, terms_.A.template topRows<nh>());
      qdot -= pinv_q_.correction(terms_.velocity.template head<nh>() + inv_dt * terms_.phi);
    }
    // C_v^+ (b_v - A_v a - (Phi_q'; Phi_v)/dt), used by both corrections.
    VecQ w = VecQ::Zero();
    if constexpr (nc > 0) {
      pinv_v_.set_rows(mass_, terms_.A);
      w = pinv_v_.pinv(-terms_.gamma - terms_.A.lazyProduct(a) - inv_dt * terms_.velocity);
      vdot += mass_.r_inverse(w);
    }
    if constexpr (Model::kHasEnergy) {
      if (energy_) vdot += energy_correction(a, w, inv_dt);
    }
    vmap<nq>(dydt) = qdot;
    vmap<nq>(dydt + nq) = vdot;
    return true;
  }

 private:
  // R^-1 N_v (C_e N_v)^+ (b_ev - A_ev a - Phi_ev / dt). Since
  // (*)_ev = (*)_e - C_e C_v^+ (*)_v, the bracket is
  // (b_e - A_e a - Phi_e / dt) - C_e w with w = C_v^+ (b_v - A_v a - vel / dt).
  VecQ energy_correction(const VecQ& a, const VecQ& w, double inv_dt) {
    const VecQ ce = mass_.rt_inverse(terms_.energy_grad_v);  // C_e^T
    VecQ u = ce;                                              // (C_e N_v)^T = N_v C_e^T
    if constexpr (nc > 0) u -= pinv_v_.pinv(pinv_v_.C().lazyProduct(ce));
    const double uu = u.squaredNorm();
    if (!(uu > tol_)) return VecQ::Zero();
    const double rhs = -terms_.energy_rate_free - terms_.energy_grad_v.dot(a) -
                       inv_dt * (terms_.energy - energy0_) - ce.dot(w);
    return mass_.r_inverse(u * (rhs / uu));
  }

  double dt_;
  bool energy_;
  double tol_;
  double energy0_ = 0;
  MechanicalTerms<Model> terms_;
  MassFactor<nq> mass_;  // one factorization of M per evaluation, shared by both row sets
  WeightedPinv<(nc > 0 ? nc : 1), nq> pinv_v_;
  WeightedPinv<(nh > 0 ? nh : 1), nq> pinv_q_;
};

struct BraunGoldfarbMethod : MechanicalMethod<BraunGoldfarbMethod> {
  static constexpr const char* kName = "braun-goldfarb";
  static constexpr const char* kDescription =
      "Braun-Goldfarb explicit constrained motion, eqs. (1)-(2), pseudo-inverses by complete orthogonal "
      "decomposition (redundant rows ok), optional energy correction";
  static std::vector<ParamSpec> generic_params() {
    return {{"dt", 0, Bound::kNonNegative, "correction time scale (s); 0 = the integrator's fixed step",
             ParamRole::kTimeScale},
            {"energy", 1, Bound::kNonNegative, "1 = energy correction on (problems with an energy law), 0 = off"},
            {"tol", 1e-6, Bound::kNonNegative, "energy correction is off where |C_e N_v|^2 <= tol"}};
  }
  // RK4 as in the paper, dt = 10 h: with dt = h the stiff correction leaves
  // an O(h^2) residual floor (docs/measurements.md).
  static ConformanceSettings conformance() {
    return {.integrator = "rk4", .step = 1e-3, .time_scale_steps = 10};
  }
  template <class Model>
  static std::vector<ParamSpec> model_params(const Model&) {
    auto specs = generic_params();
    if constexpr (!Model::kHasEnergy) {
      specs[1].default_value = 0;
      specs[1].description = "energy correction: not available, the problem has no energy law";
    }
    return specs;
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    const double energy = params.get("energy");
    if (energy != 0 && energy != 1) throw UsageError("--param energy: must be 0 or 1");
    if (energy == 1 && !Model::kHasEnergy)
      throw UsageError("--param energy=1: the problem has no energy law, energy correction cannot apply");
    return std::make_unique<BraunGoldfarbFormulation<Model>>(model, params.get("dt"), energy == 1,
                                                             params.get("tol"));
  }
};

}  // namespace cstab

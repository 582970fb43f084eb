// Penalty stabilization, the worked example of docs/extending.md made a
// method: no multipliers; the constraint rows pull the motion back through
// stiff springs and dampers,
//     M a = Q - J^T (k Phi + c Phi') - G^T c Psi,
// an ODE any integrator runs. The constraints hold only to O(|reaction| / k)
// (the springs must stretch to carry the reactions), and the stiffness makes
// explicit schemes need h ~ 1/sqrt(k) (Bayo, Garcia de Jalon & Serna, "A
// modified Lagrangian formulation for the dynamic analysis of constrained
// mechanical systems", Comput Methods Appl Mech Eng 71 (1988) 183-195, the
// penalty formulation's plain form). No KKT system: redundant rows are fine.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "linalg/small_linalg.hpp"
#include "methods/mechanical_method.hpp"

namespace cstab {

template <class Model>
class PenaltyFormulation final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  using Base::nc;
  using Base::nh;
  using Base::nq;
  using typename Base::VecQ;

  PenaltyFormulation(const Model& model, double k, double c) : Base(model), k_(k), c_(c) {}

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    VecQ f = terms_.Q;
    if constexpr (nh > 0)
      f -= terms_.A.template topRows<nh>().transpose() *
           (k_ * terms_.phi + c_ * terms_.velocity.template head<nh>());
    if constexpr (nc > nh)
      f -= terms_.A.template bottomRows<nc - nh>().transpose() * (c_ * terms_.velocity.template tail<nc - nh>());
    if (!mass_.factor(terms_.M)) {
      this->failure_ = "mass matrix not positive definite at t = " + std::to_string(t);
      return false;
    }
    vmap<nq>(dydt) = v;
    vmap<nq>(dydt + nq) = mass_.solve(f);
    return true;
  }

 private:
  double k_, c_;
  MechanicalTerms<Model> terms_;
  SmallCholesky<nq> mass_;
};

struct PenaltyMethod : MechanicalMethod<PenaltyMethod> {
  static constexpr const char* kName = "penalty";
  static constexpr const char* kDescription =
      "penalty springs: M a = Q - J^T (k Phi + c Phi') - G^T c Psi (no multipliers; residual O(1/k))";
  static std::vector<ParamSpec> generic_params() {
    return {{"k", 1e8, Bound::kPositive, "penalty stiffness (force per unit residual)"},
            {"c", 2e4, Bound::kNonNegative, "penalty damping (force per unit residual rate)", ParamRole::kRate}};
  }
  static ConformanceSettings conformance() { return {.integrator = "rk8pd", .tol = 1e-10}; }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    return std::make_unique<PenaltyFormulation<Model>>(model, params.get("k"), params.get("c"));
  }
};

}  // namespace cstab

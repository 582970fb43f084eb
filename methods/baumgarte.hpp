// Baumgarte stabilization: the constraint rows are replaced by
//     Phi'' + 2 alpha Phi' + beta^2 Phi = 0     (holonomic)
//     Psi'  + gamma Psi               = 0     (non-holonomic)
// and the accelerations and multipliers come from the augmented (KKT) system
//     [ M  A^T ] [ a      ]   [ Q                  ]
//     [ A  0   ] [ lambda ] = [ -gamma_acc - stab  ]
// which needs full-rank constraint rows.
#pragma once

#include "methods/mechanical_method.hpp"

namespace cstab {

template <class Model>
class BaumgarteFormulation final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  using Base::nc;
  using Base::nh;
  using Base::nq;
  using typename Base::VecQ;
  static constexpr int nk = nq + nc;

  BaumgarteFormulation(const Model& model, double alpha, double beta, double gamma)
      : Base(model), alpha_(alpha), beta_(beta), gamma_(gamma) {}

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    K_.setZero();
    K_.template topLeftCorner<nq, nq>() = terms_.M;
    rhs_.template head<nq>() = terms_.Q;
    if constexpr (nc > 0) {
      K_.template topRightCorner<nq, nc>() = terms_.A.transpose();
      K_.template bottomLeftCorner<nc, nq>() = terms_.A;
      Vec<double, nc> stab;
      if constexpr (nh > 0)
        stab.template head<nh>() = 2 * alpha_ * terms_.velocity.template head<nh>() + beta_ * beta_ * terms_.phi;
      if constexpr (nc > nh)
        stab.template tail<nc - nh>() = gamma_ * terms_.velocity.template tail<nc - nh>();
      rhs_.template tail<nc>() = -terms_.gamma - stab;
    }
    lu_.compute(K_);
    if (!(lu_.rcond() > 1e-15)) {
      this->failure_ = "KKT matrix singular (rcond " + std::to_string(lu_.rcond()) + ") at t = " + std::to_string(t);
      return false;
    }
    sol_ = lu_.solve(rhs_);
    vmap<nq>(dydt) = v;
    vmap<nq>(dydt + nq) = sol_.template head<nq>();
    return true;
  }

 private:
  double alpha_, beta_, gamma_;
  MechanicalTerms<Model> terms_;
  Eigen::Matrix<double, nk, nk> K_;
  Vec<double, nk> rhs_, sol_;
  Eigen::PartialPivLU<Eigen::Matrix<double, nk, nk>> lu_;
};

struct BaumgarteMethod : MechanicalMethod<BaumgarteMethod> {
  static constexpr const char* kName = "baumgarte";
  static constexpr const char* kDescription =
      "Baumgarte: Phi'' + 2 alpha Phi' + beta^2 Phi = 0, Psi' + gamma Psi = 0, KKT solve (full rank)";
  static std::vector<ParamSpec> generic_params() {
    return {{"alpha", 10, Bound::kNonNegative, "damping of the holonomic residual (1/s)"},
            {"beta", 10, Bound::kNonNegative, "stiffness of the holonomic residual (1/s)"},
            {"gamma", 10, Bound::kNonNegative, "decay rate of the non-holonomic residual (1/s)"}};
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    require_full_rank(model, kName);
    return std::make_unique<BaumgarteFormulation<Model>>(model, params.get("alpha"), params.get("beta"),
                                                         params.get("gamma"));
  }
};

}  // namespace cstab

// Baumgarte stabilization: the constraint rows are replaced by
//     Phi'' + 2 alpha Phi' + beta^2 Phi = 0     (holonomic)
//     Psi'  + gamma Psi               = 0     (non-holonomic)
// and the accelerations and multipliers come from the augmented (KKT) system
//     [ M  A^T ] [ a      ]   [ Q                  ]
//     [ A  0   ] [ lambda ] = [ -gamma_acc - stab  ]
// which needs full-rank constraint rows; it is solved through its Schur
// complement (A M^-1 A^T) lambda = -(A M^-1 Q + gamma_acc + stab).
#pragma once

#include "core/format.hpp"
#include "linalg/small_linalg.hpp"
#include "methods/mechanical_method.hpp"
#include "methods/ode_jacobian.hpp"

namespace cstab {

template <class Model>
class BaumgarteFormulation final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);

  BaumgarteFormulation(const Model& model, double alpha, double beta, double gamma)
      : Base(model), alpha_(alpha), beta_(beta), gamma_(gamma) {}

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    vmap<nq>(dydt) = v;
    if constexpr (nc == 0) {
      if (!mass_.factor(terms_.M)) return mass_failure(t);
      vmap<nq>(dydt + nq) = mass_.solve(terms_.Q);
    } else {
      const auto status = solver_.factor(terms_.M, terms_.A, 1e-15);
      if (status == SchurSolver<nq, nc>::Status::kMassNotPd) return mass_failure(t);
      if (status != SchurSolver<nq, nc>::Status::kOk) {
        this->failure_ = "constraint matrix A M^-1 A^T singular (pivot ratio " +
                         format_3g(solver_.pivot_ratio()) + ") at t = " + std::to_string(t);
        return false;
      }
      vmap<nq>(dydt + nq) = solver_.accelerations(terms_.Q, stabilized_rows());
    }
    return true;
  }

  // By AD through the KKT system (methods/ode_jacobian.hpp).
  bool has_jacobian() const override { return true; }
  bool jacobian(double t, const double* y, double* J) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    using VecC = Vec<double, nc>;
    if constexpr (nc == 0) {
      if (!mass_.factor(terms_.M)) return false;
      jac_.evaluate(this->model_, t, q, v, mass_.solve(terms_.Q), VecC(), 0, 0, 0);
      jac_.fill(J, [&](const VecQ& r, const VecC&) { return VecQ(-mass_.solve(r)); });
    } else {
      if (solver_.factor(terms_.M, terms_.A, 1e-15) != SchurSolver<nq, nc>::Status::kOk) return false;
      VecC lambda;
      const VecQ a = solver_.accelerations(terms_.Q, stabilized_rows(), &lambda);
      jac_.evaluate(this->model_, t, q, v, a, lambda, 2 * alpha_, beta_ * beta_, gamma_);
      jac_.fill(J, [&](const VecQ& r, const VecC& g) { return solver_.accelerations(-r, g); });
    }
    return true;
  }

 private:
  bool mass_failure(double t) {
    this->failure_ = "mass matrix not positive definite at t = " + std::to_string(t);
    return false;
  }

  // A a + g = 0 with g = gamma + stab, from terms_.
  Vec<double, nc> stabilized_rows() const {
    Vec<double, nc> g = terms_.gamma;
    if constexpr (nh > 0)
      g.template head<nh>() += 2 * alpha_ * terms_.velocity.template head<nh>() + beta_ * beta_ * terms_.phi;
    if constexpr (nc > nh) g.template tail<nc - nh>() += gamma_ * terms_.velocity.template tail<nc - nh>();
    return g;
  }

  double alpha_, beta_, gamma_;
  MechanicalTerms<Model> terms_;
  IndexOneJacobian<Model> jac_;
  // The KKT system [M A^T; A 0] [a; N] = [Q; -gamma - stab], solved by its
  // Schur complement A M^-1 A^T (M positive definite, A full rank).
  SchurSolver<nq, (nc > 0 ? nc : 1)> solver_;
  SmallCholesky<nq> mass_;  // no constraint rows
};

struct BaumgarteMethod : MechanicalMethod<BaumgarteMethod> {
  static constexpr const char* kName = "baumgarte";
  static constexpr bool kNeedsFullRank = true;  // redundant rows: does not apply, naming the rank
  static constexpr const char* kDescription =
      "Baumgarte: Phi'' + 2 alpha Phi' + beta^2 Phi = 0, Psi' + gamma Psi = 0, KKT solve (full rank)";
  static std::vector<ParamSpec> generic_params() {
    return {{"alpha", 10, Bound::kNonNegative, "damping of the holonomic residual (1/s)", ParamRole::kRate,
             {"beta"}},
            {"beta", 10, Bound::kNonNegative, "stiffness of the holonomic residual (1/s)"},
            {"gamma", 10, Bound::kNonNegative, "decay rate of the non-holonomic residual (1/s)"}};
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    return std::make_unique<BaumgarteFormulation<Model>>(model, params.get("alpha"), params.get("beta"),
                                                         params.get("gamma"));
  }
  static ScalableSettings scalable_settings(const Params& params) {
    return {.stabilization = ScalableSettings::Stabilization::kBaumgarte,
            .alpha = params.get("alpha"),
            .beta = params.get("beta")};
  }
};

}  // namespace cstab

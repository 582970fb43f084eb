// The penalty formulation (Bayo, Garcia de Jalon & Serna 1988, Computer
// Methods in Applied Mechanics and Engineering 71:183-195): no multipliers
// are solved for; each constraint row is a stiff spring-damper,
//     M a + A^T lambda = Q,   lambda = p (Phi'' + 2 xi omega Phi' + omega^2 Phi)   (holonomic)
//                                      p (Psi' + omega Psi)                         (non-holonomic)
// With Phi'' = A a + gamma (and Psi' likewise) the accelerations solve
//     (M + p A^T A) a = Q - p A^T (gamma + stab),
// a symmetric positive definite system whatever the rank of A: redundant
// rows are allowed. The constraints hold to O(1/p) only; it is the plain
// reference point for ali3p, whose multiplier update removes that error.
// Projected on the constraint rows the residual obeys
// Phi'' + 2 xi omega Phi' + omega^2 Phi = O(1/p), so the ODE is no stiffer
// than Baumgarte's at the same gains (rk8pd takes the same steps at the
// default alpha); a large alpha instead makes M + p A^T A ill-conditioned
// (about log10(alpha) digits of the accelerations are lost, which tight
// adaptive tolerances feel as rejected steps).
//
// p is relative to the model's mass scale, p = alpha m / a, with m the
// largest diagonal entry of M and a that of A^T A at the initial state, so
// that p A^T A weighs alpha times M whatever the units (the published
// absolute factors 1e7 to 1e9 are alpha = 1e3 to 1e7 on the usual models).
#pragma once

#include <algorithm>

#include "linalg/small_linalg.hpp"
#include "methods/mechanical_method.hpp"
#include "methods/ode_jacobian.hpp"

namespace cstab {

struct PenaltySettings {
  double alpha = 1e4;  // penalty relative to the mass scale
  double omega = 10;   // natural frequency of the holonomic residual, and decay rate of the non-holonomic one (1/s)
  double xi = 1;       // damping ratio of the holonomic residual
};

template <class Model>
class PenaltyFormulation final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);

  PenaltyFormulation(const Model& model, const PenaltySettings& s) : Base(model), settings_(s) {
    if constexpr (nc > 0) {
      VecQ q, v;
      model.initial_state(q, v);
      terms_.evaluate(model, 0.0, q, v, false);
      const Eigen::Matrix<double, nq, nq> AtA = terms_.A.transpose() * terms_.A;
      const double m = terms_.M.diagonal().cwiseAbs().maxCoeff(), a = AtA.diagonal().maxCoeff();
      penalty_ = a > 0 ? s.alpha * m / a : 0.0;
    }
  }

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    vmap<nq>(dydt) = v;
    VecQ a;
    if (!accelerations(t, a)) return false;
    vmap<nq>(dydt + nq) = a;
    return true;
  }

  // By AD (methods/ode_jacobian.hpp): with lambda = -p (A a + g), the
  // accelerations solve r = M a - Q - A^T lambda = 0, so
  // (M + p A^T A) a_x = -(r_x + p A^T g_x) at fixed (a, lambda).
  bool has_jacobian() const override { return true; }
  bool jacobian(double t, const double* y, double* J) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    VecQ a;
    if (!accelerations(t, a)) return false;
    using VecC = Vec<double, nc>;
    VecC lambda;
    if constexpr (nc > 0) lambda = -penalty_ * (terms_.A.lazyProduct(a) + stabilized_rows());
    const double w = settings_.omega;
    jac_.evaluate(this->model_, t, q, v, a, lambda, 2 * settings_.xi * w, w * w, w);
    jac_.fill(J, [&](const VecQ& r, const VecC& g) {
      if constexpr (nc > 0) return VecQ(-chol_.solve(r + penalty_ * terms_.A.transpose() * g));
      return VecQ(-chol_.solve(r));
    });
    return true;
  }

  double penalty() const { return penalty_; }

 private:
  // Phi'' = A a + g (and Psi' likewise), g with the stabilization, from terms_.
  Vec<double, nc> stabilized_rows() const {
    Vec<double, nc> g = terms_.gamma;
    const double w = settings_.omega;
    if constexpr (nh > 0)
      g.template head<nh>() += 2 * settings_.xi * w * terms_.velocity.template head<nh>() + w * w * terms_.phi;
    if constexpr (nc > nh) g.template tail<nc - nh>() += w * terms_.velocity.template tail<nc - nh>();
    return g;
  }

  // a from (M + p A^T A) a = Q - p A^T g at terms_; factors chol_.
  bool accelerations(double t, VecQ& a) {
    VecQ rhs = terms_.Q;
    W_ = terms_.M;
    if constexpr (nc > 0) {
      W_.noalias() += penalty_ * terms_.A.transpose() * terms_.A;
      rhs.noalias() -= penalty_ * terms_.A.transpose() * stabilized_rows();
    }
    if (!chol_.factor(W_)) {
      this->failure_ = "M + p A^T A not positive definite at t = " + std::to_string(t);
      return false;
    }
    a = chol_.solve(rhs);
    return true;
  }

  PenaltySettings settings_;
  double penalty_ = 0;  // p, force per unit (acceleration-level) violation
  MechanicalTerms<Model> terms_;
  IndexOneJacobian<Model> jac_;
  Eigen::Matrix<double, nq, nq> W_;
  SmallCholesky<nq> chol_;
};

struct PenaltyMethod : MechanicalMethod<PenaltyMethod> {
  static constexpr const char* kName = "penalty";
  static constexpr const char* kDescription =
      "penalty formulation (Bayo, Garcia de Jalon & Serna 1988): lambda = p (Phi'' + 2 xi omega Phi' + omega^2 "
      "Phi), no multiplier update; redundant constraints allowed";
  // The constraints and the trajectory hold to O(1/p): at the default
  // alpha = 1e4 the reference error is 1e-6 to 1e-2 on the suite's problems,
  // so the suite's accuracy checks (1e-5) run at alpha = 1e8. There the
  // accelerations carry round-off near alpha eps = 1e-8, which an adaptive
  // step at tol = 1e-10 chases with many rejected steps (ball: 3.3 s against
  // 77 ms at tol = 1e-8); hence tol = 1e-8.
  static ConformanceSettings conformance() { return {.tol = 1e-8, .params = {{"alpha", "1e8"}}}; }
  static std::vector<ParamSpec> generic_params() {
    return {{"alpha", 1e4, Bound::kPositive,
             "penalty factor relative to the mass scale: p = alpha m / a (m, a: largest diagonal entries of M and "
             "A^T A at the start)"},
            {"omega", 10, Bound::kPositive,
             "natural frequency of the holonomic residual and decay rate of the non-holonomic one (1/s)",
             ParamRole::kRate},
            {"xi", 1, Bound::kNonNegative, "damping ratio of the holonomic residual"}};
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    PenaltySettings s;
    s.alpha = params.get("alpha");
    s.omega = params.get("omega");
    s.xi = params.get("xi");
    return std::make_unique<PenaltyFormulation<Model>>(model, s);
  }
};

}  // namespace cstab

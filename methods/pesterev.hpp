// Pesterev-Matrosov-Morozov lambda-feedback (control-based) stabilization.
// Each output f_i of relative degree r_i is made to obey
//     (d/dt + lambda_i)^{r_i} f_i = 0                      (eq. 7, repeated roots)
// which, with eq. (4), gives the linear system for the reactions
//     A(X) N + phi(X, lambda) = 0,   phi_i = L_F^{r_i} f_i + sum_{k<r_i} C(r_i,k) lambda_i^{r_i-k} L_F^k f_i
// (eqs. 8-10). N is substituted into X' = F + B N and any integrator steps it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/format.hpp"
#include "core/formulation.hpp"
#include "core/params.hpp"
#include "core/problem.hpp"
#include "linalg/dense.hpp"
#include "linalg/small_linalg.hpp"
#include "methods/affine.hpp"
#include "methods/contracts.hpp"
#include "methods/mechanical.hpp"
#include "methods/mechanical_method.hpp"

namespace cstab {

namespace pesterev_detail {
inline double binomial(int n, int k) {
  double r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}
// lambda_<constraint> if given (> 0), else lambda.
inline double lambda_for(const Params& params, const std::string& constraint) {
  const double own = params.get("lambda_" + constraint);
  return own > 0 ? own : params.get("lambda");
}
}  // namespace pesterev_detail

template <class Model>
class PesterevFormulation final : public AffineFormulationBase<Model> {
  using Base = AffineFormulationBase<Model>;

 public:
  using Base::m;
  using Base::n;

  PesterevFormulation(const Model& model, const Params& params) : Base(model) {
    for (int i = 0; i < m; ++i) {
      const double li = pesterev_detail::lambda_for(params, this->constraints_[i].name);
      const int r = Model::kRelativeDegree[i];
      // gains_(i, k) multiplies L_F^k f_i.
      for (int k = 0; k < LieJet<Model>::kMaxDegree; ++k)
        gains_(i, k) = k < r ? pesterev_detail::binomial(r, k) * std::pow(li, r - k) : 0.0;
    }
    // Relative degrees are declared by the model; check them where the run
    // starts: A(X0) must be nonsingular.
    Vec<double, n> X0;
    this->model_.initial_state(X0);
    jet_.evaluate(this->model_, 0.0, X0);
    const double rcond = linalg::lu_rcond_of(jet_.A);
    if (!(rcond > 1e-12))
      throw UsageError("pesterev: declared relative degrees do not hold at the initial state "
                       "(A(X0) singular, rcond " + format_3g(rcond) + ")");
  }

  bool rhs(double t, const double* y, double* dydt) override {
    const Eigen::Map<const Vec<double, n>> X(y);
    jet_.evaluate(this->model_, t, X);
    Vec<double, m> phi = jet_.top;
    for (int i = 0; i < m; ++i) phi(i) += jet_.lower.row(i).dot(gains_.row(i));
    lu_.compute(jet_.A.data());
    // Singularity check from the LU pivots (min |U_ii| / max |U_ii|): the
    // 1-norm rcond estimate cost a third of this right-hand side (docs/measurements.md, Speed).
    const double ratio = lu_.pivot_ratio();
    if (!(ratio > 1e-14)) {
      this->failure_ = "reaction matrix A(X) singular (LU pivot ratio " + format_3g(ratio) + ") at t = " +
                 std::to_string(t);
      return false;
    }
    Vec<double, m> N = -phi;
    lu_.solve(N.data(), N.data());
    vmap<n>(dydt) = jet_.F + jet_.B * N;
    return true;
  }
  bool has_condition_number() const override { return true; }
  double condition_number(double t, const double* y) override {
    jet_.evaluate(this->model_, t, vmap<n>(y));
    return linalg::condition_number_of(jet_.A);
  }

 private:
  Eigen::Matrix<double, m, LieJet<Model>::kMaxDegree> gains_;
  LieJet<Model> jet_;
  // Dynamic-size LU, compiled once (linalg/dense.cpp), instead of Eigen's
  // fixed-size PartialPivLU compiled again in every pair.
  linalg::Lu lu_{m};
};

// Lambda-feedback on a mechanical model, written directly in its terms. With
// X = [q; v], F = [v; a], a = M^-1 Q, B = [0; M^-1 A^T] (MechanicalAsAffine),
// the Lie derivatives are L_F Phi = J v + Phi_t, L_F^2 Phi = J a + gamma_h,
// L_F Psi = G a + gamma_n and L_B L_F^{r-1} f = A M^-1 A^T, so eq. (9) reads
//   (A M^-1 A^T) N = -(A a + gamma + [2 lambda Phi' + lambda^2 Phi; lambda Psi]).
// This fast path avoids nesting AD through M^-1 Q; a test checks it against
// the generic LieJet on MechanicalAsAffine.
template <class Model>
class PesterevMechanicalFormulation final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);

  PesterevMechanicalFormulation(const Model& model, const Params& params) : Base(model) {
    for (int i = 0; i < nc; ++i) lambda_(i) = pesterev_detail::lambda_for(params, this->constraints_[i].name);
    VecQ q, v;
    model.initial_state(q, v);
    if (build(0.0, q, v, 1e-12) != Solver::Status::kOk)
      throw UsageError("pesterev: A(X0) = A M^-1 A^T is singular at the initial state (pivot ratio " +
                       format_3g(solver_.pivot_ratio()) + "): redundant constraints; use braun-goldfarb or projection");
  }

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    if (build(t, q, v, 1e-14) != Solver::Status::kOk) return false;
    // A a + g = 0 with g = gamma + the feedback terms.
    Vec<double, nc> g = terms_.gamma;
    for (int i = 0; i < nc; ++i) {
      const double l = lambda_(i);
      g(i) += i < nh ? 2 * l * terms_.velocity(i) + l * l * terms_.phi(i) : l * terms_.velocity(i);
    }
    vmap<nq>(dydt) = v;
    vmap<nq>(dydt + nq) = solver_.accelerations(terms_.Q, g);
    return true;
  }

  bool has_condition_number() const override { return true; }
  double condition_number(double t, const double* y) override {
    if (build(t, vmap<nq>(y).eval(), vmap<nq>(y + nq).eval(), 0.0) == Solver::Status::kMassNotPd) return NAN;
    return linalg::condition_number_of(solver_.schur());
  }

 private:
  using Solver = SchurSolver<nq, nc>;

  // Terms at (t, q, v) and the factorizations of M and A M^-1 A^T (the
  // reaction matrix of eq. 9, symmetric positive definite for full-rank rows).
  typename Solver::Status build(double t, const VecQ& q, const VecQ& v, double min_pivot_ratio) {
    terms_.evaluate(this->model_, t, q, v, false);
    const auto status = solver_.factor(terms_.M, terms_.A, min_pivot_ratio);
    if (status == Solver::Status::kMassNotPd)
      this->failure_ = "mass matrix not positive definite at t = " + std::to_string(t);
    else if (status == Solver::Status::kSingular)
      this->failure_ = "reaction matrix A(X) = A M^-1 A^T singular (pivot ratio " +
                       format_3g(solver_.pivot_ratio()) + ") at t = " + std::to_string(t);
    return status;
  }

  Vec<double, nc> lambda_;
  MechanicalTerms<Model> terms_;
  Solver solver_;
};

// Registry entry: applies to any problem with an affine (state-space) model,
// and to any mechanical model through MechanicalAsAffine.
struct PesterevMethod {
  static constexpr const char* kName = "pesterev";
  static constexpr const char* kDescription =
      "lambda-feedback: (d/dt + lambda)^r f = 0 per output, reactions from A(X) N + phi = 0 "
      "(Pesterev-Matrosov-Morozov); runs on the state-space form or on a mechanical model as an affine system";
  static std::vector<ParamSpec> generic_params() {
    // lambda = 6: of the gains 1.9, 6, 19, 60, 190, 600, 1900 tuned on every
    // problem (matrices/tuned.toml), 6 costs within 1.5x of the cheapest
    // setting reaching each accuracy level in 22 of 23 rk4 cases and within
    // 3x in 24 of 29 rk8pd ones; 60 in 12 of 23 and 16 of 29
    // (docs/measurements.md "Tuned gains"). The paper's 1500 is for Adams at
    // h = 1e-5; it diverges with rk4 at h = 1e-2 and makes rk8pd stiff.
    return {{"lambda", 6, Bound::kPositive, "repeated root -lambda of every output's characteristic equation",
             ParamRole::kRate}};
  }
  static ConformanceSettings conformance() { return {.params = {{"lambda", "50"}}}; }

  template <class P>
  static std::string why_not(const P& p) {
    static_assert(contracts::check_problem<P>());
    if constexpr (contracts::HasStateSpace<P>) {
      return "";
    } else if constexpr (contracts::HasMechanical<P>) {
      return redundancy_why_not(p.mechanical(), kName);  // A M^-1 A^T must be regular
    } else {
      return "problem has neither an affine (state-space) nor a mechanical model";
    }
  }

  template <class P>
  static std::vector<ParamSpec> params(const P& p, const std::string& formulation) {
    static_assert(contracts::check_problem<P>());
    auto specs = generic_params();
    for (const auto& c : constraints_of(p, formulation))
      specs.push_back({"lambda_" + c.name, 0, Bound::kNonNegative,
                       "lambda for output '" + c.name + "' (0 = use lambda)"});
    return specs;
  }

  template <class P>
  static std::unique_ptr<Formulation> make(const P& p, const std::string& formulation, const Params& params) {
    static_assert(contracts::check_problem<P>());
    if constexpr (contracts::HasStateSpace<P>) {
      if (formulation.empty() || formulation == p.state_space().formulation_name()) {
        using Model = std::decay_t<decltype(p.state_space())>;
        return std::make_unique<PesterevFormulation<Model>>(p.state_space(), params);
      }
    }
    if constexpr (contracts::HasMechanical<P>) {
      if (formulation.empty() || formulation == p.mechanical().formulation_name()) {
        using Model = std::decay_t<decltype(p.mechanical())>;
        return std::make_unique<PesterevMechanicalFormulation<Model>>(p.mechanical(), params);
      }
    }
    throw UsageError("--formulation " + formulation + ": pesterev cannot run on it");
  }

 private:
  template <class P>
  static std::vector<ConstraintInfo> constraints_of(const P& p, const std::string& formulation) {
    if constexpr (contracts::HasStateSpace<P>) {
      if (formulation.empty() || formulation == p.state_space().formulation_name())
        return p.state_space().constraints();
    }
    if constexpr (contracts::HasMechanical<P>) {
      if (formulation.empty() || formulation == p.mechanical().formulation_name())
        return p.mechanical().constraints();
    }
    throw UsageError("--formulation " + formulation + ": pesterev cannot run on it");
  }
};

}  // namespace cstab

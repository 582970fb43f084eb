// The affine (state-space) form of Pesterev et al., eqs. (1)-(4):
//     X' = F(t, X) + B(t, X) N,   outputs f_i(t, X) = 0, i = 1..m,
// with N the m unknown reactions and r_i the relative degree of output i.
//
// A model type provides (sizes fixed at compile time; the concept
// contracts::AffineModel in methods/contracts.hpp checks it):
//   static constexpr int kStates, kInputs;
//   static constexpr std::array<int, kInputs> kRelativeDegree;   // each >= 1
//   template <class S> void drift(const S& t, const Vec<S, kStates>& X, Vec<S, kStates>& F) const;
//   void input_matrix(double t, const Vec<double, kStates>& X, Eigen::Matrix<double, kStates, kInputs>& B) const;
//   template <class S> void outputs(const S& t, const Vec<S, kStates>& X, Vec<S, kInputs>& f) const;
//   std::string formulation_name() const;
//   std::vector<ConstraintInfo> constraints() const;               // one per output
//   void initial_state(Vec<double, kStates>& X) const;
//   void to_canonical(double t, const Vec<double, kStates>& X, double* canonical) const;
// and optionally closed_form_jet (LieJet below).
//
// LieJet computes, by nested forward-mode AD, everything lambda-feedback
// needs: L_F^k f_i for k < r_i, the rows A_i = L_B L_F^{r_i-1} f_i and
// L_F^{r_i} f_i (eq. 4). Time enters as a state moving with unit speed
// along F, so time-dependent outputs need nothing extra.
#pragma once

#include <algorithm>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/vec.hpp"
#include "linalg/dense.hpp"
#include "methods/contract_detail.hpp"

namespace cstab {

template <class Model>
class LieJet;

namespace contracts::detail {
// The exact call LieJet makes of the optional closed-form jet.
template <class M>
inline constexpr bool closed_form_jet_exact =
    requires(const M& m, double t, const Vec<double, M::kStates>& X, LieJet<M>& jet) {
      m.closed_form_jet(t, X, jet);
    };
}  // namespace contracts::detail

template <class Model>
class LieJet {
 public:
  static constexpr int n = Model::kStates;
  static constexpr int m = Model::kInputs;
  static constexpr int kMaxDegree =
      *std::max_element(Model::kRelativeDegree.begin(), Model::kRelativeDegree.end());
  using Outer = ad::Dual<m + 1>;  // directions: B columns, then F

  // A(i, :) = L_B L_F^{r_i - 1} f_i; top(i) = L_F^{r_i} f_i;
  // lower(i, k) = L_F^k f_i for k < r_i.
  Eigen::Matrix<double, m, m> A;
  Vec<double, m> top;
  Eigen::Matrix<double, m, kMaxDegree> lower;
  Vec<double, n> F;
  Eigen::Matrix<double, n, m> B;

  // A model may provide the jet in closed form,
  //   template <class Jet> void closed_form_jet(double t, const Vec<double, n>& X, Jet& jet) const;
  // filling F, B, A, top and lower as evaluate_ad would (a hand-derived fast
  // path: its test compares it with evaluate_ad). Otherwise nested AD. A
  // member named closed_form_jet with another signature is an error.
  static constexpr bool has_closed_form() {
    constexpr bool exact = contracts::detail::closed_form_jet_exact<Model>;
    static_assert(exact || !contracts::detail::names_closed_form_jet<Model>, CSTAB_CONTRACT_MSG_CLOSED_FORM_JET);
    return exact;
  }
  void evaluate(const Model& model, double t, const Vec<double, n>& X) {
    if constexpr (has_closed_form())
      model.closed_form_jet(t, X, *this);
    else
      evaluate_ad(model, t, X);
  }

  void evaluate_ad(const Model& model, double t, const Vec<double, n>& X) {
    model.drift(t, X, F);
    model.input_matrix(t, X, B);
    Vec<Outer, n> Y;
    for (int i = 0; i < n; ++i) {
      Eigen::Matrix<double, m + 1, 1> d;
      d.template head<m>() = B.row(i).transpose();
      d(m) = F(i);
      Y(i) = Outer(X(i), d);
    }
    Eigen::Matrix<double, m + 1, 1> dt = Eigen::Matrix<double, m + 1, 1>::Zero();
    dt(m) = 1.0;
    const Outer tY(t, dt);
    lift<kMaxDegree - 1>(model, tY, Y);
  }

 private:
  template <int L, class T>
  void lift(const Model& model, const T& t, const Vec<T, n>& Z) {
    if constexpr (L == 0) {
      Vec<T, m> f;
      model.outputs(t, Z, f);
      std::array<Outer, kMaxDegree> levels;
      for (int i = 0; i < m; ++i) {
        ad::extract_levels<Outer>(f(i), levels.data());
        const int r = Model::kRelativeDegree[i];
        for (int k = 0; k < kMaxDegree; ++k) lower(i, k) = k < r ? levels[k].value() : 0.0;
        const Outer& last = levels[r - 1];
        A.row(i) = last.derivatives().template head<m>().transpose();
        top(i) = last.derivatives()(m);
      }
    } else {
      using N = ad::Nest<T>;
      Vec<T, n> FZ;
      model.drift(t, Z, FZ);
      Vec<N, n> Zn;
      for (int i = 0; i < n; ++i) Zn(i) = N(Z(i), Eigen::Matrix<T, 1, 1>(FZ(i)));
      const N tn(t, Eigen::Matrix<T, 1, 1>(T(1.0)));
      lift<L - 1>(model, tn, Zn);
    }
  }
};

// Shared parts of every formulation whose state is an affine model's X.
template <class Model>
class AffineFormulationBase : public Formulation {
 public:
  static constexpr int n = Model::kStates;
  static constexpr int m = Model::kInputs;

  explicit AffineFormulationBase(const Model& model) : model_(model), constraints_(model.constraints()) {}

  std::string formulation_name() const override { return model_.formulation_name(); }
  int dimension() const override { return n; }
  void initial_state(double* y) const override {
    Vec<double, n> X;
    model_.initial_state(X);
    vmap<n>(y) = X;
  }
  const std::vector<ConstraintInfo>& constraints() const override { return constraints_; }
  void residuals(double t, const double* y, double* out) const override {
    Vec<double, m> f;
    model_.outputs(t, vmap<n>(y).eval(), f);
    vmap<m>(out) = f;
  }
  void to_canonical(double t, const double* y, double* c) const override {
    model_.to_canonical(t, vmap<n>(y).eval(), c);
  }
  const std::string& failure_reason() const override { return failure_; }

 protected:
  Model model_;
  std::vector<ConstraintInfo> constraints_;
  std::string failure_;
};


}  // namespace cstab

// A mechanical model seen as an affine system (Pesterev et al. eq. 1-2), so
// that lambda-feedback runs on every mechanical problem:
//     X = [q; v],  F = [v; M^-1 Q],  B = [0; M^-1 A^T],  N = the multipliers,
//     outputs [Phi (relative degree 2); Psi (relative degree 1)].
#pragma once

#include <array>

#include "methods/mechanical.hpp"

namespace cstab {

template <class Model>
class MechanicalAsAffine {
 public:
  static constexpr int nq = Model::kCoords;
  static constexpr int nh = Model::kHolonomic;
  static constexpr int nn = Model::kNonholonomic;
  static constexpr int kStates = 2 * nq;
  static constexpr int kInputs = nh + nn;
  static constexpr std::array<int, kInputs> kRelativeDegree = [] {
    std::array<int, kInputs> r{};
    for (int i = 0; i < kInputs; ++i) r[i] = i < nh ? 2 : 1;
    return r;
  }();

  explicit MechanicalAsAffine(const Model& model) : model_(model) {}

  std::string formulation_name() const { return model_.formulation_name(); }
  std::vector<ConstraintInfo> constraints() const { return model_.constraints(); }
  void initial_state(Vec<double, kStates>& X) const {
    Vec<double, nq> q, v;
    model_.initial_state(q, v);
    X << q, v;
  }
  void to_canonical(double t, const Vec<double, kStates>& X, double* c) const {
    model_.to_canonical(t, X.template head<nq>().eval(), X.template tail<nq>().eval(), c);
  }

  template <class S>
  void drift(const S& t, const Vec<S, kStates>& X, Vec<S, kStates>& F) const {
    const Vec<S, nq> q = X.template head<nq>(), v = X.template tail<nq>();
    Eigen::Matrix<S, nq, nq> M;
    Vec<S, nq> Q;
    model_.mass(t, q, M);
    model_.forces(t, q, v, Q);
    F.template head<nq>() = v;
    F.template tail<nq>() = ad::spd_solve<S, nq>(M, Q);
  }

  void input_matrix(double t, const Vec<double, kStates>& X, Eigen::Matrix<double, kStates, kInputs>& B) const {
    const Vec<double, nq> q = X.template head<nq>(), v = X.template tail<nq>();
    MechanicalTerms<Model> terms;
    terms.evaluate_velocity(model_, t, q, v);
    Eigen::Matrix<double, nq, nq> M;
    model_.mass(t, q, M);
    B.template topRows<nq>().setZero();
    B.template bottomRows<nq>() = M.llt().solve(terms.A.transpose());
  }

  template <class S>
  void outputs(const S& t, const Vec<S, kStates>& X, Vec<S, kInputs>& f) const {
    const Vec<S, nq> q = X.template head<nq>(), v = X.template tail<nq>();
    if constexpr (nh > 0) {
      Vec<S, nh> phi;
      model_.holonomic(t, q, phi);
      f.template head<nh>() = phi;
    }
    if constexpr (nn > 0) {
      Vec<S, nn> psi;
      model_.nonholonomic(t, q, v, psi);
      f.template tail<nn>() = psi;
    }
  }

 private:
  Model model_;
};

}  // namespace cstab

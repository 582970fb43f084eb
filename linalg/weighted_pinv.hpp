// Mass-weighted pseudo-inverse machinery shared by the mechanical methods:
// M = R^T R (R upper Cholesky factor), C = A R^-1, and corrections
// R^-1 C^+ r with C^+ from a complete orthogonal decomposition, so that
// redundant (rank-deficient) constraint rows are handled (Braun-Goldfarb
// Sec. 2.2.2). R^-1 C^+ r is the M-norm-smallest dq with A dq = r in the
// least-squares sense. One MassFactor serves every row set at a state. The
// decomposition runs on dynamic sizes (linalg::Cod, compiled once in
// linalg/dense.cpp, storage allocated at construction): a fixed-size
// Eigen::CompleteOrthogonalDecomposition cost about 6 s of compile time per
// size and translation unit.
#pragma once

#include <Eigen/Dense>

#include "linalg/dense.hpp"
#include "linalg/small_linalg.hpp"

namespace cstab {

template <int N>
class MassFactor {
 public:
  using VecN = Eigen::Matrix<double, N, 1>;

  // Returns false if M is not positive definite.
  bool factor(const Eigen::Matrix<double, N, N>& M) { return chol_.factor(M); }
  VecN solve(const VecN& b) const { return chol_.solve(b); }
  // R^-1 w (R = L^T)
  VecN r_inverse(const VecN& w) const { return chol_.solve_upper(w); }
  // R^-T a = L^-1 a (a row a^T times R^-1, as a column)
  VecN rt_inverse(const VecN& a) const { return chol_.solve_lower(a); }
  // R^-T B
  template <int K>
  Eigen::Matrix<double, N, K> rt_inverse_matrix(const Eigen::Matrix<double, N, K>& B) const {
    return chol_.solve_lower_matrix(B);
  }

 private:
  SmallCholesky<N> chol_;
};

template <int K, int N>
class WeightedPinv {
 public:
  using VecN = Eigen::Matrix<double, N, 1>;
  using VecK = Eigen::Matrix<double, K, 1>;

  WeightedPinv() : cod_(K, N) {}

  // `mass` must outlive the corrections computed with these rows.
  void set_rows(const MassFactor<N>& mass, const Eigen::Matrix<double, K, N>& A) {
    mass_ = &mass;
    const Eigen::Matrix<double, N, K> At = A.transpose();
    C_ = mass.rt_inverse_matrix(At).transpose();  // C^T = R^-T A^T
    cod_.compute(C_.data());
  }
  int rank() const { return cod_.rank(); }
  const Eigen::Matrix<double, K, N>& C() const { return C_; }

  // R^-1 C^+ r
  VecN correction(const VecK& r) const { return mass_->r_inverse(pinv(r)); }
  // C^+ r (in R-coordinates)
  VecN pinv(const VecK& r) const {
    VecN x;
    cod_.solve(r.data(), x.data());
    return x;
  }

 private:
  const MassFactor<N>* mass_ = nullptr;
  Eigen::Matrix<double, K, N> C_;
  linalg::Cod cod_;
};

}  // namespace cstab

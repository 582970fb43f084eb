// Mass-weighted pseudo-inverse machinery shared by the mechanical methods:
// M = R^T R (R upper Cholesky factor), C = A R^-1, and corrections
// R^-1 C^+ r with C^+ from a complete orthogonal decomposition, so that
// redundant (rank-deficient) constraint rows are handled (Braun-Goldfarb
// Sec. 2.2.2). R^-1 C^+ r is the M-norm-smallest dq with A dq = r in the
// least-squares sense.
#pragma once

#include <Eigen/Dense>

namespace cstab {

template <int K, int N>
class WeightedPinv {
 public:
  using VecN = Eigen::Matrix<double, N, 1>;
  using VecK = Eigen::Matrix<double, K, 1>;

  // Returns false if M is not positive definite.
  bool factor_mass(const Eigen::Matrix<double, N, N>& M) {
    llt_.compute(M);
    return llt_.info() == Eigen::Success;
  }
  VecN mass_solve(const VecN& b) const { return llt_.solve(b); }

  void set_rows(const Eigen::Matrix<double, K, N>& A) {
    // C^T = R^-T A^T = L^-1 A^T
    Ct_ = llt_.matrixL().solve(A.transpose());
    C_ = Ct_.transpose();
    cod_.compute(C_);
  }
  int rank() const { return int(cod_.rank()); }
  const Eigen::Matrix<double, K, N>& C() const { return C_; }

  // R^-1 C^+ r
  VecN correction(const VecK& r) const { return r_inverse(cod_.solve(r)); }
  // C^+ r (unscaled, in R-coordinates)
  VecN pinv(const VecK& r) const { return cod_.solve(r); }
  VecN r_inverse(const VecN& w) const { return llt_.matrixU().solve(w); }
  // C_e = a^T R^-1 as a column: R^-T a = L^-1 a
  VecN row_times_r_inverse(const VecN& a) const { return llt_.matrixL().solve(a); }

 private:
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt_;
  Eigen::Matrix<double, N, K> Ct_;
  Eigen::Matrix<double, K, N> C_;
  Eigen::CompleteOrthogonalDecomposition<Eigen::Matrix<double, K, N>> cod_;
};

}  // namespace cstab

// Dense linear algebra for the small fixed sizes of the mechanical models
// (4..12 coordinates, 2..9 constraint rows), as plain loops with
// compile-time bounds. Eigen's LLT and triangular solves on fixed-size
// matrices of these sizes dispatch to its blocked (BLAS-like) kernels with
// packing, which dominated the right-hand sides in the profile (docs/measurements.md,
// Speed); these loops compute the same factorization (tests/unit/test_small_linalg.cpp
// checks them against Eigen's LLT and against a KKT solve).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace cstab {

// M = L L^T for a symmetric positive definite N x N matrix (lower triangle read).
template <int N>
class SmallCholesky {
 public:
  using Mat = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;

  // False if M is not positive definite (a pivot <= 0 or not finite).
  bool factor(const Mat& M) {
    double min_pivot = 0, max_diag = 0;
    for (int j = 0; j < N; ++j) {
      double d = M(j, j);
      for (int k = 0; k < j; ++k) d -= L_(j, k) * L_(j, k);
      if (!(d > 0) || !std::isfinite(d)) {
        pivot_ratio_ = 0;
        return false;
      }
      min_pivot = j == 0 ? d : std::min(min_pivot, d);
      max_diag = std::max(max_diag, M(j, j));
      const double ljj = std::sqrt(d);
      L_(j, j) = ljj;
      inv_diag_(j) = 1.0 / ljj;
      for (int i = j + 1; i < N; ++i) {
        double s = M(i, j);
        for (int k = 0; k < j; ++k) s -= L_(i, k) * L_(j, k);
        L_(i, j) = s * inv_diag_(j);
      }
    }
    pivot_ratio_ = min_pivot / max_diag;
    return true;
  }

  // min pivot / max diagonal entry of M: >= 1 / cond_2(M), so a tiny value
  // flags a (numerically) singular matrix.
  double pivot_ratio() const { return pivot_ratio_; }

  // L^-1 b, in place.
  template <class V>
  void solve_lower_in_place(V& b) const {
    for (int i = 0; i < N; ++i) {
      double s = b(i);
      for (int k = 0; k < i; ++k) s -= L_(i, k) * b(k);
      b(i) = s * inv_diag_(i);
    }
  }
  // L^-T b, in place.
  template <class V>
  void solve_upper_in_place(V& b) const {
    for (int i = N - 1; i >= 0; --i) {
      double s = b(i);
      for (int k = i + 1; k < N; ++k) s -= L_(k, i) * b(k);
      b(i) = s * inv_diag_(i);
    }
  }
  VecN solve_lower(VecN b) const { solve_lower_in_place(b); return b; }
  VecN solve_upper(VecN b) const { solve_upper_in_place(b); return b; }
  // M^-1 b
  VecN solve(VecN b) const {
    solve_lower_in_place(b);
    solve_upper_in_place(b);
    return b;
  }
  // L^-1 B for an N x K matrix.
  template <int K>
  Eigen::Matrix<double, N, K> solve_lower_matrix(Eigen::Matrix<double, N, K> B) const {
    for (int c = 0; c < K; ++c) {
      auto col = B.col(c);
      solve_lower_in_place(col);
    }
    return B;
  }
  const Mat& L() const { return L_; }
  const VecN& inv_diag() const { return inv_diag_; }

 private:
  Mat L_ = Mat::Zero();
  VecN inv_diag_ = VecN::Zero();
  double pivot_ratio_ = 0;
};

// Accelerations of M a = Q + A^T N with full-rank rows A (NC x NQ), through
// the Schur complement S = A M^-1 A^T (symmetric positive definite) instead
// of the (NQ + NC)-square KKT system: with M = L L^T and C^T = L^-1 A^T,
// S = C C^T, and M^-1 A^T N = L^-T (C^T N). For row conditions
// A a + g = 0: S N = -(A a_free + g), a = a_free + M^-1 A^T N.
template <int NQ, int NC>
class SchurSolver {
 public:
  using VecQ = Eigen::Matrix<double, NQ, 1>;
  using VecC = Eigen::Matrix<double, NC, 1>;
  using MatCQ = Eigen::Matrix<double, NC, NQ>;
  using MatC = Eigen::Matrix<double, NC, NC>;

  enum class Status { kOk, kMassNotPd, kSingular };

  // Factors M, then S; `min_pivot_ratio` is the singularity threshold on S.
  Status factor(const Eigen::Matrix<double, NQ, NQ>& M, const MatCQ& A, double min_pivot_ratio) {
    if (!mass_.factor(M)) return Status::kMassNotPd;
    // C^T = L^-1 A^T by forward substitution on whole rows: the NC columns
    // advance together (independent, vectorizable chains). One triangular
    // solve per column was latency-bound and took ~40 % of the andrews and
    // ball right-hand sides (docs/measurements.md, Speed).
    const auto& L = mass_.L();
    S_.setZero();
    for (int i = 0; i < NQ; ++i) {
      RowC r = A.col(i).transpose();
      for (int k = 0; k < i; ++k) r -= L(i, k) * Ct_.row(k);
      Ct_.row(i) = r * mass_.inv_diag()(i);
      // S = C C^T = sum_i (row i of C^T)^T (row i of C^T).
      S_.noalias() += Ct_.row(i).transpose() * Ct_.row(i);
    }
    if (!schur_.factor(S_) || !(schur_.pivot_ratio() > min_pivot_ratio)) return Status::kSingular;
    return Status::kOk;
  }
  // a with M a = Q + A^T N, A a + g = 0 (and N, if asked): with y = L^-1 Q,
  // A a_free = C y, so S N = -(C y + g) and a = L^-T (y + C^T N): one
  // forward and one back substitution with L (free_acceleration, then
  // reaction_acceleration, take three).
  VecQ accelerations(const VecQ& Q, const VecC& g, VecC* multipliers_out = nullptr) const {
    VecQ y = Q;
    mass_.solve_lower_in_place(y);
    const VecC N = schur_.solve(-(Ct_.transpose().lazyProduct(y) + g));
    y.noalias() += Ct_.lazyProduct(N);
    mass_.solve_upper_in_place(y);
    if (multipliers_out) *multipliers_out = N;
    return y;
  }
  // a_free = M^-1 Q
  VecQ free_acceleration(const VecQ& Q) const { return mass_.solve(Q); }
  // N with S N = r
  VecC multipliers(const VecC& r) const { return schur_.solve(r); }
  // M^-1 A^T N
  VecQ reaction_acceleration(const VecC& N) const {
    VecQ w = Ct_.lazyProduct(N);
    mass_.solve_upper_in_place(w);
    return w;
  }
  // S (both triangles)
  MatC schur() const { return S_.template selfadjointView<Eigen::Lower>(); }
  double pivot_ratio() const { return schur_.pivot_ratio(); }

 private:
  using RowC = Eigen::Matrix<double, 1, NC>;
  using MatQC = Eigen::Matrix<double, NQ, NC, (NC == 1 ? Eigen::ColMajor : Eigen::RowMajor)>;
  SmallCholesky<NQ> mass_;
  SmallCholesky<NC> schur_;
  MatQC Ct_ = MatQC::Zero();
  MatC S_ = MatC::Zero();
};

}  // namespace cstab

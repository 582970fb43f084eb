// Cold-path dense linear algebra on dynamic sizes, compiled once
// (linalg/dense.cpp): rank checks, condition numbers, reciprocal condition
// estimates. These run once per run or once per observation, never in a
// right-hand side, so they need not be fixed-size; instantiating Eigen's
// rank-revealing decompositions for every fixed size in every translation
// unit was most of the build's cost. Matrices are column-major raw arrays.
#pragma once

#include <Eigen/Core>
#include <memory>

namespace cstab::linalg {

// Numerical rank (complete orthogonal decomposition, Eigen's default threshold).
int rank(const double* a, int rows, int cols);
// 2-norm condition number of an n x n matrix by SVD (infinite if singular).
double condition_number(const double* a, int n);
// Reciprocal condition estimate (1-norm) of an n x n matrix from its partial-pivoting LU.
double lu_rcond(const double* a, int n);
// x = A^-1 b by partial-pivoting LU of an n x n matrix; returns its reciprocal condition estimate.
double lu_solve(const double* a, int n, const double* b, double* x);
// x = M^-1 b by LDLT of a symmetric n x n matrix (robust Cholesky).
void ldlt_solve(const double* m, int n, const double* b, double* x);
// Largest modulus of the eigenvalues of a general (nonsymmetric) n x n
// matrix, by Eigen's real Schur form; NaN if it does not converge. A
// fixed-size EigenSolver costs seconds of compile time per size and unit.
double spectral_radius(const double* a, int n);

template <class Derived>
int rank_of(const Eigen::MatrixBase<Derived>& a) {
  const Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> m = a;
  return rank(m.data(), int(m.rows()), int(m.cols()));
}
template <class Derived>
double condition_number_of(const Eigen::MatrixBase<Derived>& a) {
  const Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> m = a;
  return condition_number(m.data(), int(m.rows()));
}
template <class Derived>
double spectral_radius_of(const Eigen::MatrixBase<Derived>& a) {
  const Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> m = a;
  return spectral_radius(m.data(), int(m.rows()));
}
template <class Derived>
double lu_rcond_of(const Eigen::MatrixBase<Derived>& a) {
  const Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> m = a;
  return lu_rcond(m.data(), int(m.rows()));
}

}  // namespace cstab::linalg

namespace cstab::linalg {

// Least-squares minimum-norm solves x = C^+ r with a complete orthogonal
// decomposition of a rows x cols matrix (rank-revealing: redundant rows are
// fine). Storage is allocated once, at construction; compute() and solve()
// do not allocate.
class Cod {
 public:
  Cod(int rows, int cols);
  ~Cod();
  Cod(const Cod&) = delete;
  Cod& operator=(const Cod&) = delete;
  Cod(Cod&&) noexcept;
  Cod& operator=(Cod&&) noexcept;

  void compute(const double* c);            // column-major rows x cols
  void solve(const double* r, double* x) const;  // r: rows, x: cols
  int rank() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Partial-pivoting LU of an n x n matrix, for the Newton iterations of the
// implicit schemes (generalized-alpha and its kin, ali3p): compiled once for
// every size, where Eigen's fixed-size PartialPivLU is compiled again for
// each size in every method's pair unit; unrolled kernels for n <= 8.
// Storage is allocated at construction; compute() and solve() do not
// allocate. A singular matrix gives a non-finite solution.
class Lu {
 public:
  explicit Lu(int n);
  ~Lu();
  Lu(const Lu&) = delete;
  Lu& operator=(const Lu&) = delete;
  Lu(Lu&&) noexcept;
  Lu& operator=(Lu&&) noexcept;

  void compute(const double* a);                 // column-major n x n
  void solve(const double* b, double* x) const;  // x = A^-1 b; x may alias b
  void solve_columns(const double* b, double* x, int columns) const;  // column-major n x columns; may alias
  int size() const;
  // After compute(): min |u_ii| / max |u_ii| (0 if singular, 1 for n = 0):
  // a cheap singularity indicator, as BandLu's (linalg/band.hpp).
  double pivot_ratio() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cstab::linalg

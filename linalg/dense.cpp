#include "linalg/dense.hpp"

#include <Eigen/Dense>
#include <limits>

namespace cstab::linalg {

using Map = Eigen::Map<const Eigen::MatrixXd>;

int rank(const double* a, int rows, int cols) {
  if (rows == 0 || cols == 0) return 0;
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(Map(a, rows, cols));
  return int(cod.rank());
}

double condition_number(const double* a, int n) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Map(a, n, n));
  const auto& s = svd.singularValues();
  return s(n - 1) > 0 ? s(0) / s(n - 1) : std::numeric_limits<double>::infinity();
}

double lu_rcond(const double* a, int n) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(Map(a, n, n));
  return lu.rcond();
}

double lu_solve(const double* a, int n, const double* b, double* x) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(Map(a, n, n));
  Eigen::Map<Eigen::VectorXd>(x, n) = lu.solve(Eigen::Map<const Eigen::VectorXd>(b, n));
  return lu.rcond();
}

void ldlt_solve(const double* m, int n, const double* b, double* x) {
  Eigen::Map<Eigen::VectorXd>(x, n) = Map(m, n, n).ldlt().solve(Eigen::Map<const Eigen::VectorXd>(b, n));
}

}  // namespace cstab::linalg

namespace cstab::linalg {

// Cod's rank decision: a pivot below kCodRankThreshold times the largest counts as
// zero. Rows that are redundant on the constraint manifold (bricard's twelve
// rows of rank 11) regain full rank a residual r away from it, with a
// smallest singular value of order r; with Eigen's default threshold (about
// 1e-15 relative) the pseudo-inverse then returned multipliers of order 1/r,
// and none, projection and braun-goldfarb diverged on bricard within 2 s
// (rk4, h = 1e-3). 1e-5 is the square root of the Schur path's pivot
// threshold on A M^-1 A^T (1e-10, methods/index1.hpp), whose pivots are the
// squares of these: both paths call the same states redundant.
constexpr double kCodRankThreshold = 1e-5;

struct Cod::Impl {
  Impl(int rows, int cols) : cod(rows, cols), matrix(rows, cols), rhs(rows), x(cols) {
    cod.setThreshold(kCodRankThreshold);
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  Eigen::MatrixXd matrix;
  Eigen::VectorXd rhs;
  mutable Eigen::VectorXd x;
};

Cod::Cod(int rows, int cols) : impl_(std::make_unique<Impl>(rows, cols)) {}
Cod::~Cod() = default;
Cod::Cod(Cod&&) noexcept = default;
Cod& Cod::operator=(Cod&&) noexcept = default;

void Cod::compute(const double* c) {
  impl_->matrix = Map(c, impl_->matrix.rows(), impl_->matrix.cols());
  impl_->cod.compute(impl_->matrix);
}

void Cod::solve(const double* r, double* x) const {
  Eigen::Map<const Eigen::VectorXd> rv(r, impl_->matrix.rows());
  impl_->x.noalias() = impl_->cod.solve(rv);
  Eigen::Map<Eigen::VectorXd>(x, impl_->matrix.cols()) = impl_->x;
}

int Cod::rank() const { return int(impl_->cod.rank()); }

}  // namespace cstab::linalg

#include "linalg/dense.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

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

double spectral_radius(const double* a, int n) {
  if (n == 0) return 0;
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(Map(a, n, n), /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
  return solver.eigenvalues().cwiseAbs().maxCoeff();
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
  Impl(int rows, int cols)
      : cod(rows, cols), matrix(rows, cols), c(rows), y(cols) {
    cod.setThreshold(kCodRankThreshold);
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  Eigen::MatrixXd matrix;
  // solve()'s workspaces: Eigen's own COD solve allocates its Q^T r, its
  // reflectors' products and (for the in-place permutation) a mask on every
  // call.
  mutable Eigen::VectorXd c, y;
};

Cod::Cod(int rows, int cols) : impl_(std::make_unique<Impl>(rows, cols)) {}
Cod::~Cod() = default;
Cod::Cod(Cod&&) noexcept = default;
Cod& Cod::operator=(Cod&&) noexcept = default;

void Cod::compute(const double* c) {
  impl_->matrix = Map(c, impl_->matrix.rows(), impl_->matrix.cols());
  impl_->cod.compute(impl_->matrix);
}

namespace {
// x <- (I - tau [1; e][1; e]^T) x for x = [x0; xt]: a Householder reflector
// on a vector, written out (Eigen's applyHouseholderOnTheLeft goes through
// general products on dynamic blocks, which allocate).
template <class Tail, class Essential>
void reflect(double& x0, Tail&& xt, const Essential& e, double tau) {
  const double w = x0 + e.dot(xt);
  x0 -= tau * w;
  xt -= (tau * w) * e;
}
}  // namespace

// x = P Z^T [T11^-1 (Q^T r)(0:rank); 0], the steps of Eigen's
// CompleteOrthogonalDecomposition::_solve_impl (Eigen 3.4) on preallocated
// vectors, with the reflectors applied by hand.
void Cod::solve(const double* r, double* x) const {
  Impl& m = *impl_;
  const Eigen::Index rank = m.cod.rank(), rows = m.matrix.rows(), cols = m.matrix.cols();
  Eigen::Map<Eigen::VectorXd> xv(x, cols);
  if (rank == 0) {
    xv.setZero();
    return;
  }
  const Eigen::MatrixXd& qtz = m.cod.matrixQTZ();
  // c = Q^T r, Q = H(0) ... H(rank-1): H(k)'s essential part is below the
  // diagonal in column k.
  m.c = Eigen::Map<const Eigen::VectorXd>(r, rows);
  for (Eigen::Index k = 0; k < rank; ++k)
    reflect(m.c(k), m.c.tail(rows - k - 1), qtz.col(k).tail(rows - k - 1), m.cod.hCoeffs()(k));
  m.cod.matrixT().topLeftCorner(rank, rank).template triangularView<Eigen::Upper>().solveInPlace(m.c.head(rank));
  m.y.head(rank) = m.c.head(rank);
  m.y.tail(cols - rank).setZero();
  // Z^T: reflector k acts on entries k and rank .. cols-1 (its essential
  // part is row k of the top-right block).
  if (rank < cols)
    for (Eigen::Index k = 0; k < rank; ++k)
      reflect(m.y(k), m.y.tail(cols - rank), qtz.row(k).tail(cols - rank).transpose(), m.cod.zCoeffs()(k));
  xv = m.cod.colsPermutation() * m.y;
}

int Cod::rank() const { return int(impl_->cod.rank()); }

// Unblocked, column by column: a Newton matrix has a few to a few dozen
// rows, too few for blocking to pay (docs/build.md).
struct Lu::Impl {
  explicit Impl(int n) : n(n), lu(std::size_t(n) * std::size_t(n)), pivot(std::size_t(n)) {}
  int n;
  std::vector<double> lu;  // L below the diagonal (unit diagonal implied), U on and above
  std::vector<int> pivot;  // row k was exchanged with row pivot[k] at step k
};

Lu::Lu(int n) : impl_(std::make_unique<Impl>(n)) {}
Lu::~Lu() = default;
Lu::Lu(Lu&&) noexcept = default;
Lu& Lu::operator=(Lu&&) noexcept = default;

int Lu::size() const { return impl_->n; }

double Lu::pivot_ratio() const {
  const int n = impl_->n;
  if (n == 0) return 1;
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (int k = 0; k < n; ++k) {
    const double u = std::abs(impl_->lu[std::size_t(k) * std::size_t(n) + std::size_t(k)]);
    if (!(u == u)) return 0;  // NaN
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  return hi > 0 ? lo / hi : 0;
}

namespace {

// The factorization and the solve for n rows; N > 0 fixes n at compile time
// (N = n), so that the loops of the small sizes unroll, N = 0 leaves it
// dynamic. Both are compiled here only, for N = 0 .. kLuFixedMax.
template <int N>
void lu_factor(int n_dynamic, double* m, int* pivot) {
  const int n = N > 0 ? N : n_dynamic;
  for (int k = 0; k < n; ++k) {
    double* ck = m + std::size_t(k) * n;
    int p = k;
    double best = std::abs(ck[k]);
    for (int i = k + 1; i < n; ++i)
      if (std::abs(ck[i]) > best) best = std::abs(ck[i]), p = i;
    pivot[k] = p;
    if (p != k)
      for (int j = 0; j < n; ++j) std::swap(m[std::size_t(j) * n + k], m[std::size_t(j) * n + p]);
    // A zero pivot leaves infinities and NaNs in the factors, as Eigen's
    // does: the callers test the solution for finiteness.
    const double inv = 1.0 / ck[k];
    for (int i = k + 1; i < n; ++i) ck[i] *= inv;
    for (int j = k + 1; j < n; ++j) {
      double* cj = m + std::size_t(j) * n;
      const double akj = cj[k];
      for (int i = k + 1; i < n; ++i) cj[i] -= ck[i] * akj;
    }
  }
}

template <int N>
void lu_solve_factored(int n_dynamic, const double* m, const int* pivot, double* x) {
  const int n = N > 0 ? N : n_dynamic;
  for (int k = 0; k < n; ++k) std::swap(x[k], x[pivot[k]]);
  for (int k = 0; k < n; ++k) {  // L y = P b, column-oriented
    const double* ck = m + std::size_t(k) * n;
    const double xk = x[k];
    for (int i = k + 1; i < n; ++i) x[i] -= ck[i] * xk;
  }
  for (int k = n - 1; k >= 0; --k) {  // U x = y
    const double* ck = m + std::size_t(k) * n;
    x[k] /= ck[k];
    const double xk = x[k];
    for (int i = 0; i < k; ++i) x[i] -= ck[i] * xk;
  }
}

constexpr int kLuFixedMax = 8;

template <class Call, int... Ns>
void lu_dispatch(int n, Call&& call, std::integer_sequence<int, Ns...>) {
  // The unrolled kernel of n's size where there is one, the dynamic one
  // otherwise.
  const bool fixed = ((n == Ns + 1 ? (call(std::integral_constant<int, Ns + 1>{}), true) : false) || ...);
  if (!fixed) call(std::integral_constant<int, 0>{});
}

}  // namespace

void Lu::compute(const double* a) {
  const int n = impl_->n;
  double* m = impl_->lu.data();
  int* pivot = impl_->pivot.data();
  std::copy(a, a + std::size_t(n) * std::size_t(n), m);
  lu_dispatch(
      n, [&](auto size) { lu_factor<decltype(size)::value>(n, m, pivot); },
      std::make_integer_sequence<int, kLuFixedMax>{});
}

void Lu::solve(const double* b, double* x) const {
  const int n = impl_->n;
  if (x != b) std::copy(b, b + n, x);
  const double* m = impl_->lu.data();
  const int* pivot = impl_->pivot.data();
  lu_dispatch(
      n, [&](auto size) { lu_solve_factored<decltype(size)::value>(n, m, pivot, x); },
      std::make_integer_sequence<int, kLuFixedMax>{});
}

void Lu::solve_columns(const double* b, double* x, int columns) const {
  const std::size_t n = std::size_t(impl_->n);
  for (int j = 0; j < columns; ++j) solve(b + j * n, x + j * n);
}

}  // namespace cstab::linalg

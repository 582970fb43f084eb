// linalg::Cod, the rank-revealing least-squares solve behind every
// mass-weighted pseudo-inverse (linalg/weighted_pinv.hpp), against an
// independent formulation: the SVD pseudo-inverse with the same relative
// rank cut (singular values below 1e-5 of the largest dropped; Cod's
// threshold is on the QR pivots, which bracket the singular values within
// a factor of order the size, so the test matrices keep their nonzero
// singular values far above the cut).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "linalg/dense.hpp"

namespace cstab {
namespace {

Eigen::VectorXd svd_pinv_solve(const Eigen::MatrixXd& a, const Eigen::VectorXd& r) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& s = svd.singularValues();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(a.cols());
  for (Eigen::Index i = 0; i < s.size(); ++i)
    if (s(i) > 1e-5 * s(0)) x += svd.matrixV().col(i) * (svd.matrixU().col(i).dot(r) / s(i));
  return x;
}

void expect_matches_svd(const Eigen::MatrixXd& a, int expected_rank, unsigned seed) {
  std::srand(seed);
  linalg::Cod cod(int(a.rows()), int(a.cols()));
  cod.compute(a.data());
  EXPECT_EQ(cod.rank(), expected_rank);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd r = Eigen::VectorXd::Random(a.rows());
    Eigen::VectorXd x(a.cols());
    cod.solve(r.data(), x.data());
    const Eigen::VectorXd expected = svd_pinv_solve(a, r);
    EXPECT_LT((x - expected).norm(), 1e-12 * (1 + expected.norm())) << "rows " << a.rows() << " cols " << a.cols();
  }
}

TEST(Cod, FullRankWideIsTheMinimumNormSolution) {
  std::srand(1);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(3, 7);
  expect_matches_svd(a, 3, 2);
}

TEST(Cod, RedundantRowsGiveTheLeastSquaresMinimumNormSolution) {
  // Rank 3 of 5 rows (two rows repeated as combinations), 8 columns: the
  // Z reflectors (rank < cols) and the column permutation both act.
  std::srand(3);
  Eigen::MatrixXd a(5, 8);
  a.topRows(3) = Eigen::MatrixXd::Random(3, 8);
  a.row(3) = 2 * a.row(0) - a.row(2);
  a.row(4) = a.row(1);
  expect_matches_svd(a, 3, 4);
}

TEST(Cod, TallAndSquareRankDeficient) {
  std::srand(5);
  Eigen::MatrixXd tall = Eigen::MatrixXd::Random(6, 4);
  tall.col(3) = tall.col(0) + tall.col(1);
  expect_matches_svd(tall, 3, 6);
  Eigen::MatrixXd square = Eigen::MatrixXd::Random(4, 4);
  square.row(2) = square.row(0);
  expect_matches_svd(square, 3, 7);
}

TEST(Cod, ZeroMatrixGivesZero) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2, 3);
  linalg::Cod cod(2, 3);
  cod.compute(a.data());
  EXPECT_EQ(cod.rank(), 0);
  const double r[2] = {1, -2};
  double x[3] = {7, 7, 7};
  cod.solve(r, x);
  for (double xi : x) EXPECT_EQ(xi, 0.0);
}

// The residual of the solve, relative: ||A x - b|| / (||A|| ||x|| + ||b||).
double relative_residual(const Eigen::MatrixXd& a, const Eigen::VectorXd& x, const Eigen::VectorXd& b) {
  return (a * x - b).norm() / (a.norm() * x.norm() + b.norm());
}

TEST(Lu, SolvesAgainstAClosedFormInverse) {
  // [[2, 1], [1, 1]]^-1 = [[1, -1], [-1, 2]]: x = (1*3 - 1*5, -3 + 2*5) = (-2, 7).
  const double a[4] = {2, 1, 1, 1};  // column-major
  linalg::Lu lu(2);
  EXPECT_EQ(lu.size(), 2);
  lu.compute(a);
  const double b[2] = {3, 5};
  double x[2];
  lu.solve(b, x);
  EXPECT_NEAR(x[0], -2, 1e-15);
  EXPECT_NEAR(x[1], 7, 1e-15);
}

TEST(Lu, NeedsPivotingAndMatchesFullPivotingLu) {
  // A zero leading entry: no LU without row exchanges exists.
  Eigen::MatrixXd a(3, 3);
  a << 0, 2, 1, 1, 0, 3, 4, 1, 0;
  const Eigen::VectorXd b = Eigen::Vector3d(1, -2, 5);
  linalg::Lu lu(3);
  lu.compute(a.data());
  Eigen::VectorXd x(3);
  lu.solve(b.data(), x.data());
  const Eigen::VectorXd expected = a.fullPivLu().solve(b);
  EXPECT_LT((x - expected).norm(), 1e-14 * expected.norm());
}

TEST(Lu, RefactorsAndSolvesInPlaceAtKktSizes) {
  // A KKT-like system [M -A^T; A 0], the shape the Newton iterations solve,
  // refactored twice with one object; x aliasing b gives the same answer.
  std::srand(11);
  for (int n : {5, 21, 40}) {
    linalg::Lu lu(n);
    for (int round = 0; round < 2; ++round) {
      const int nq = 2 * n / 3, nc = n - nq;
      Eigen::MatrixXd m = Eigen::MatrixXd::Random(nq, nq);
      m = m * m.transpose() + Eigen::MatrixXd::Identity(nq, nq);
      const Eigen::MatrixXd c = Eigen::MatrixXd::Random(nc, nq);
      Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
      k.topLeftCorner(nq, nq) = m;
      k.topRightCorner(nq, nc) = -c.transpose();
      k.bottomLeftCorner(nc, nq) = c;
      const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
      lu.compute(k.data());
      Eigen::VectorXd x(n);
      lu.solve(b.data(), x.data());
      EXPECT_LT(relative_residual(k, x, b), 1e-14) << "n = " << n;
      Eigen::VectorXd inplace = b;
      lu.solve(inplace.data(), inplace.data());
      EXPECT_EQ((inplace - x).norm(), 0.0) << "n = " << n;
    }
  }
}

TEST(Lu, SolvesSeveralColumnsAsEachAlone) {
  std::srand(13);
  const int n = 7, columns = 4;
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(n, n) + 4 * Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, columns);
  linalg::Lu lu(n);
  lu.compute(a.data());
  Eigen::MatrixXd x = b;
  lu.solve_columns(x.data(), x.data(), columns);
  EXPECT_LT((a * x - b).norm(), 1e-13 * b.norm());
  for (int j = 0; j < columns; ++j) {
    Eigen::VectorXd alone(n);
    lu.solve(b.col(j).data(), alone.data());
    EXPECT_EQ((x.col(j) - alone).norm(), 0.0) << j;
  }
}

// Eigenvalues known in closed form: a scaled rotation (r e^{+-i theta}), an
// upper-triangular matrix (its diagonal), the companion matrix of
// (x - 1)(x + 3)(x - 0.5) = x^3 + 1.5 x^2 - 4 x + 1.5 (roots 1, -3, 0.5).
TEST(SpectralRadius, MatchesClosedForms) {
  const double r = 2.5, theta = 0.7;
  Eigen::Matrix2d rotation;
  rotation << r * std::cos(theta), -r * std::sin(theta), r * std::sin(theta), r * std::cos(theta);
  EXPECT_NEAR(linalg::spectral_radius_of(rotation), r, 1e-13);
  Eigen::Matrix3d triangular;
  triangular << 1, 5, -7, 0, -4, 2, 0, 0, 3;
  EXPECT_NEAR(linalg::spectral_radius_of(triangular), 4.0, 1e-13);
  Eigen::Matrix3d companion;
  companion << -1.5, 4, -1.5, 1, 0, 0, 0, 1, 0;
  EXPECT_NEAR(linalg::spectral_radius_of(companion), 3.0, 1e-12);
  EXPECT_EQ(linalg::spectral_radius(nullptr, 0), 0.0);
}

}  // namespace
}  // namespace cstab

// The fixed-size Cholesky of linalg/small_linalg.hpp against Eigen: the
// factor and solves against Eigen's LLT (the Schur-complement solver is in
// test_schur_solver.cpp: apart, each unit compiles in under 1 GB).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "linalg/small_linalg.hpp"
#include "tests/support/random_spd.hpp"

namespace cstab {
namespace {

using testing_support::random_spd;

// |a - b| for a fixed-size and a dynamic-size vector of the same length.
template <class A, class B>
double distance(const A& a, const B& b) {
  double sum = 0;
  for (int i = 0; i < int(a.size()); ++i) sum += (a(i) - b(i)) * (a(i) - b(i));
  return std::sqrt(sum);
}

template <int N>
void check_cholesky() {
  std::mt19937 rng(N);
  for (int trial = 0; trial < 20; ++trial) {
    const auto M = random_spd<N>(rng);
    const Eigen::Matrix<double, N, 1> b = Eigen::Matrix<double, N, 1>::Random();
    SmallCholesky<N> chol;
    ASSERT_TRUE(chol.factor(M));
    // References on dynamic sizes: compiled once, not once per N.
    const Eigen::MatrixXd Md = M;
    const Eigen::VectorXd bd = b;
    const Eigen::LLT<Eigen::MatrixXd> llt(Md);
    const Eigen::MatrixXd L = llt.matrixL();
    EXPECT_LT((chol.L().template triangularView<Eigen::Lower>().toDenseMatrix() - L).norm(), 1e-12 * L.norm());
    const Eigen::VectorXd x = llt.solve(bd), xl = llt.matrixL().solve(bd), xu = llt.matrixU().solve(bd);
    EXPECT_LT(distance(chol.solve(b), x), 1e-10 * x.norm());
    EXPECT_LT(distance(chol.solve_lower(b), xl), 1e-10 * b.norm() * 1e3);
    EXPECT_LT(distance(chol.solve_upper(b), xu), 1e-10 * xu.norm());
    // pivot ratio bounds 1 / cond_2 from above
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Md);
    EXPECT_GE(chol.pivot_ratio(), eig.eigenvalues()(0) / eig.eigenvalues()(N - 1) * (1 - 1e-12));
  }
}

TEST(SmallCholesky, MatchesEigenLlt) {
  check_cholesky<2>();
  check_cholesky<4>();
  check_cholesky<9>();
  check_cholesky<12>();
}

// 1 x 1 (the Schur complement of a single constraint row) in closed form.
TEST(SmallCholesky, OneByOne) {
  SmallCholesky<1> chol;
  ASSERT_TRUE(chol.factor(Eigen::Matrix<double, 1, 1>(4.0)));
  EXPECT_DOUBLE_EQ(chol.L()(0, 0), 2.0);
  EXPECT_DOUBLE_EQ(chol.solve(Eigen::Matrix<double, 1, 1>(2.0))(0), 0.5);
  EXPECT_DOUBLE_EQ(chol.solve_lower(Eigen::Matrix<double, 1, 1>(2.0))(0), 1.0);
  EXPECT_DOUBLE_EQ(chol.solve_upper(Eigen::Matrix<double, 1, 1>(2.0))(0), 1.0);
  EXPECT_DOUBLE_EQ(chol.pivot_ratio(), 1.0);
}

TEST(SmallCholesky, RefusesIndefiniteAndSingular) {
  SmallCholesky<3> chol;
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  M(2, 2) = -1;
  EXPECT_FALSE(chol.factor(M));
  M(2, 2) = 0;
  EXPECT_FALSE(chol.factor(M));
  M(2, 2) = 1e-20;
  ASSERT_TRUE(chol.factor(M));
  EXPECT_LT(chol.pivot_ratio(), 1e-19);
}

}  // namespace
}  // namespace cstab

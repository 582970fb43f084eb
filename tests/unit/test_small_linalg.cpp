// The fixed-size loops of linalg/small_linalg.hpp against Eigen: the
// Cholesky factor and solves against Eigen's LLT, the Schur-complement
// constrained accelerations against a full-pivoting LU of the KKT system.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "linalg/small_linalg.hpp"

namespace cstab {
namespace {

template <int N>
Eigen::Matrix<double, N, N> random_spd(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Matrix<double, N, N> B;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) B(i, j) = u(rng);
  return B * B.transpose() + 0.1 * Eigen::Matrix<double, N, N>::Identity();
}

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

template <int NQ, int NC>
void check_schur() {
  std::mt19937 rng(NQ * 100 + NC);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const auto M = random_spd<NQ>(rng);
    Eigen::Matrix<double, NC, NQ> A;
    for (int i = 0; i < NC; ++i)
      for (int j = 0; j < NQ; ++j) A(i, j) = u(rng);
    const Eigen::Matrix<double, NQ, 1> Q = Eigen::Matrix<double, NQ, 1>::Random();
    const Eigen::Matrix<double, NC, 1> g = Eigen::Matrix<double, NC, 1>::Random();
    // KKT: [M -A^T; A 0] [a; N] = [Q; -g]  (M a = Q + A^T N, A a + g = 0)
    // The reference KKT solve on dynamic sizes (compiled once).
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(NQ + NC, NQ + NC);
    K.topLeftCorner(NQ, NQ) = M;
    K.topRightCorner(NQ, NC) = -A.transpose();
    K.bottomLeftCorner(NC, NQ) = A;
    Eigen::VectorXd rhs(NQ + NC);
    rhs << Q, -g;
    const Eigen::VectorXd xd = K.fullPivLu().solve(rhs);
    const Eigen::Matrix<double, NQ + NC, 1> x = xd;

    SCOPED_TRACE(::testing::Message() << "NQ " << NQ << " NC " << NC << " trial " << trial);
    SchurSolver<NQ, NC> s;
    ASSERT_EQ(s.factor(M, A, 1e-14), (SchurSolver<NQ, NC>::Status::kOk));
    const Eigen::Matrix<double, NQ, 1> a_free = s.free_acceleration(Q);
    const Eigen::Matrix<double, NC, 1> N = s.multipliers(-(A * a_free + g));
    const Eigen::Matrix<double, NQ, 1> a = a_free + s.reaction_acceleration(N);
    EXPECT_LT((a - x.template head<NQ>()).norm(), 1e-9 * (1 + x.norm()));
    EXPECT_LT((N - x.template tail<NC>()).norm(), 1e-9 * (1 + x.norm()));
    EXPECT_LT((s.schur() - A * Eigen::MatrixXd(M).inverse() * A.transpose()).norm(), 1e-10 * s.schur().norm());
    // The two-substitution path the methods use.
    Eigen::Matrix<double, NC, 1> N2;
    const Eigen::Matrix<double, NQ, 1> a2 = s.accelerations(Q, g, &N2);
    EXPECT_LT((a2 - x.template head<NQ>()).norm(), 1e-9 * (1 + x.norm()));
    EXPECT_LT((N2 - x.template tail<NC>()).norm(), 1e-9 * (1 + x.norm()));
    EXPECT_LT((M * a2 - Q - A.transpose() * N2).norm(), 1e-9 * (1 + Q.norm()));
    EXPECT_LT((A * a2 + g).norm(), 1e-9 * (1 + g.norm()));
  }
}

TEST(SchurSolver, MatchesKktSolve) {
  check_schur<4, 2>();
  check_schur<9, 9>();
  check_schur<12, 9>();
  check_schur<3, 1>();
}

TEST(SchurSolver, FlagsRedundantRows) {
  std::mt19937 rng(7);
  const auto M = random_spd<4>(rng);
  Eigen::Matrix<double, 2, 4> A;
  A << 1, 2, 3, 4, 2, 4, 6, 8;  // the second row twice the first
  SchurSolver<4, 2> s;
  EXPECT_EQ(s.factor(M, A, 1e-14), (SchurSolver<4, 2>::Status::kSingular));
}

}  // namespace
}  // namespace cstab

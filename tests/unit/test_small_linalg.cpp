// The fixed-size loops of linalg/small_linalg.hpp against Eigen: the
// Cholesky factor and solves against Eigen's LLT, the Schur-complement
// constrained accelerations against a full-pivoting LU of the KKT system.
#include <gtest/gtest.h>

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

template <int N>
void check_cholesky() {
  std::mt19937 rng(N);
  for (int trial = 0; trial < 20; ++trial) {
    const auto M = random_spd<N>(rng);
    const Eigen::Matrix<double, N, 1> b = Eigen::Matrix<double, N, 1>::Random();
    SmallCholesky<N> chol;
    ASSERT_TRUE(chol.factor(M));
    const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(M);
    const Eigen::Matrix<double, N, N> L = llt.matrixL();
    EXPECT_LT((chol.L().template triangularView<Eigen::Lower>().toDenseMatrix() - L).norm(), 1e-12 * L.norm());
    EXPECT_LT((chol.solve(b) - llt.solve(b)).norm(), 1e-10 * llt.solve(b).norm());
    EXPECT_LT((chol.solve_lower(b) - llt.matrixL().solve(b)).norm(), 1e-10 * b.norm() * 1e3);
    EXPECT_LT((chol.solve_upper(b) - llt.matrixU().solve(b)).norm(), 1e-10 * llt.matrixU().solve(b).norm());
    // pivot ratio bounds 1 / cond_2 from above
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(M);
    EXPECT_GE(chol.pivot_ratio(), eig.eigenvalues()(0) / eig.eigenvalues()(N - 1) * (1 - 1e-12));
  }
}

TEST(SmallCholesky, MatchesEigenLlt) {
  check_cholesky<1>();
  check_cholesky<4>();
  check_cholesky<9>();
  check_cholesky<12>();
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
    Eigen::Matrix<double, NQ + NC, NQ + NC> K = Eigen::Matrix<double, NQ + NC, NQ + NC>::Zero();
    K.template topLeftCorner<NQ, NQ>() = M;
    K.template topRightCorner<NQ, NC>() = -A.transpose();
    K.template bottomLeftCorner<NC, NQ>() = A;
    Eigen::Matrix<double, NQ + NC, 1> rhs;
    rhs << Q, -g;
    const Eigen::Matrix<double, NQ + NC, 1> x = K.fullPivLu().solve(rhs);

    SCOPED_TRACE(::testing::Message() << "NQ " << NQ << " NC " << NC << " trial " << trial);
    SchurSolver<NQ, NC> s;
    ASSERT_EQ(s.factor(M, A, 1e-14), (SchurSolver<NQ, NC>::Status::kOk));
    const Eigen::Matrix<double, NQ, 1> a_free = s.free_acceleration(Q);
    const Eigen::Matrix<double, NC, 1> N = s.multipliers(-(A * a_free + g));
    const Eigen::Matrix<double, NQ, 1> a = a_free + s.reaction_acceleration(N);
    EXPECT_LT((a - x.template head<NQ>()).norm(), 1e-9 * (1 + x.norm()));
    EXPECT_LT((N - x.template tail<NC>()).norm(), 1e-9 * (1 + x.norm()));
    EXPECT_LT((s.schur() - A * M.inverse() * A.transpose()).norm(), 1e-10 * s.schur().norm());
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

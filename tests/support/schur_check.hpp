// The Schur-complement solver of linalg/small_linalg.hpp against an
// independent formulation: the KKT system [M -A^T; A 0] [a; N] = [Q; -g]
// solved by a full-pivoting LU on dynamic sizes, for random SPD M and full
// rank A (test_schur_solver.cpp and test_schur_solver_large.cpp: one unit
// for the small sizes, one for the large, each under 1 GB to compile).
#pragma once

#include <gtest/gtest.h>

#include <random>

#include "linalg/small_linalg.hpp"
#include "tests/support/random_spd.hpp"

namespace cstab::testing_support {

// The checks of check_schur, on dynamic sizes (compiled once, not once per
// size): KKT [M -A^T; A 0] [a; N] = [Q; -g] (M a = Q + A^T N, A a + g = 0)
// solved by a full-pivoting LU; a, N from the solver's three-call path,
// a2, N2 from its two-substitution path (the methods'), S its Schur
// complement A M^-1 A^T.
inline void expect_schur_matches_kkt(const Eigen::MatrixXd& M, const Eigen::MatrixXd& A, const Eigen::VectorXd& Q,
                                     const Eigen::VectorXd& g, const Eigen::VectorXd& a, const Eigen::VectorXd& N,
                                     const Eigen::MatrixXd& S, const Eigen::VectorXd& a2, const Eigen::VectorXd& N2) {
  const Eigen::Index nq = M.rows(), nc = A.rows();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nq + nc, nq + nc);
  K.topLeftCorner(nq, nq) = M;
  K.topRightCorner(nq, nc) = -A.transpose();
  K.bottomLeftCorner(nc, nq) = A;
  Eigen::VectorXd rhs(nq + nc);
  rhs << Q, -g;
  const Eigen::VectorXd x = K.fullPivLu().solve(rhs);
  EXPECT_LT((a - x.head(nq)).norm(), 1e-9 * (1 + x.norm()));
  EXPECT_LT((N - x.tail(nc)).norm(), 1e-9 * (1 + x.norm()));
  EXPECT_LT((S - A * M.inverse() * A.transpose()).norm(), 1e-10 * S.norm());
  EXPECT_LT((a2 - x.head(nq)).norm(), 1e-9 * (1 + x.norm()));
  EXPECT_LT((N2 - x.tail(nc)).norm(), 1e-9 * (1 + x.norm()));
  EXPECT_LT((M * a2 - Q - A.transpose() * N2).norm(), 1e-9 * (1 + Q.norm()));
  EXPECT_LT((A * a2 + g).norm(), 1e-9 * (1 + g.norm()));
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
    SCOPED_TRACE(::testing::Message() << "NQ " << NQ << " NC " << NC << " trial " << trial);
    SchurSolver<NQ, NC> s;
    ASSERT_EQ(s.factor(M, A, 1e-14), (SchurSolver<NQ, NC>::Status::kOk));
    const Eigen::Matrix<double, NQ, 1> a_free = s.free_acceleration(Q);
    const Eigen::Matrix<double, NC, 1> N = s.multipliers(-(A * a_free + g));
    const Eigen::Matrix<double, NQ, 1> a = a_free + s.reaction_acceleration(N);
    Eigen::Matrix<double, NC, 1> N2;
    const Eigen::Matrix<double, NQ, 1> a2 = s.accelerations(Q, g, &N2);
    expect_schur_matches_kkt(M, A, Q, g, a, N, s.schur(), a2, N2);
  }
}

}  // namespace cstab::testing_support

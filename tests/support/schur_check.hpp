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

}  // namespace cstab::testing_support

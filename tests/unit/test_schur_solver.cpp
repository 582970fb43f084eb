// The Schur-complement solver of linalg/small_linalg.hpp against a
// full-pivoting LU of the KKT system (tests/support/schur_check.hpp), small
// sizes and redundant rows; the large sizes are in test_schur_solver_large.cpp,
// the Cholesky in test_small_linalg.cpp.
#include <gtest/gtest.h>

#include <random>

#include "linalg/small_linalg.hpp"
#include "tests/support/random_spd.hpp"
#include "tests/support/schur_check.hpp"

namespace cstab {
namespace {

using testing_support::check_schur;
using testing_support::random_spd;

TEST(SchurSolver, MatchesKktSolve) {
  check_schur<4, 2>();
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

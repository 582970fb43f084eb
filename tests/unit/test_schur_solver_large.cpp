// The Schur-complement solver of linalg/small_linalg.hpp against a
// full-pivoting LU of the KKT system (tests/support/schur_check.hpp) at the
// sizes of the larger models (9 and 12 coordinates, 9 rows); apart from the
// small sizes so that each unit compiles in under 1 GB.
#include <gtest/gtest.h>

#include "tests/support/schur_check.hpp"

namespace cstab {
namespace {

TEST(SchurSolver, MatchesKktSolveLarge) {
  testing_support::check_schur<9, 9>();
  testing_support::check_schur<12, 9>();
}

}  // namespace
}  // namespace cstab

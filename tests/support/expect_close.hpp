// Comparison of a closed-form result with its AD counterpart, shared by the
// closed-form tests (tests/unit/test_closed_forms.cpp, tests/unit/test_wheel.cpp).
#pragma once

#include <gtest/gtest.h>

namespace cstab::testing {

// max |a - b| <= 1e-13 (1 + max |b|), printing both on failure.
template <class A, class B>
void expect_matches_ad(const A& a, const B& b, const char* what) {
  const double scale = 1 + b.cwiseAbs().maxCoeff();
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-13 * scale) << what << "\n" << a << "\nvs AD\n" << b;
}

}  // namespace cstab::testing

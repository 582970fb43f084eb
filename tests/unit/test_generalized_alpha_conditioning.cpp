// The generalized-alpha family's iteration matrix
// (methods/generalized_alpha.hpp) on a Cartesian pendulum, against what
// Bottasso, Bauchau & Cardona (2007) prove: the scaling keeps its condition
// number bounded as h -> 0, while the plain one grows like h^-2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "linalg/dense.hpp"
#include "methods/generalized_alpha.hpp"
#include "tests/support/order_util.hpp"

namespace cstab {
namespace {

using testing::log_slope;

// ---- conditioning of the Newton matrix ----

// Planar pendulum in Cartesian coordinates (mass 2, length 1.5).
class Pendulum {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = false;
  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const { return {{"length", "holonomic", "x^2 + y^2 - L^2"}}; }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << 1.5 * std::sin(0.7), -1.5 * std::cos(0.7);
    v << 0.3 * std::cos(0.7), 0.3 * std::sin(0.7);
  }
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
  template <class S>
  void mass(const S&, const Vec<S, 2>&, Eigen::Matrix<S, 2, 2>& M) const {
    M = 2.0 * Eigen::Matrix<S, 2, 2>::Identity();
  }
  template <class S>
  void forces(const S&, const Vec<S, 2>&, const Vec<S, 2>& v, Vec<S, 2>& Q) const {
    Q(0) = -0.1 * v(0);
    Q(1) = -2.0 * 9.81 - 0.1 * v(1);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - 2.25;
  }
};

template <bool kIndex2>
void expect_scaled_condition_bounded() {
  GeneralizedAlphaFormulation<Pendulum, kIndex2> scheme(Pendulum{}, "test", AlphaSettings{});
  using F = decltype(scheme);
  Vec<double, F::kDim> y;
  scheme.initial_state(y.data());
  std::vector<double> hs, scaled, plain;
  for (double h = 1e-2; h >= 0.99e-6; h /= 10) {
    // 2-norm condition number by SVD, compiled once in linalg (a fixed-size
    // JacobiSVD here cost seconds of compile time per size).
    auto cond = [](const typename F::MatN& S) { return linalg::condition_number_of(S); };
    hs.push_back(h);
    scaled.push_back(cond(scheme.newton_matrix(0.0, y.data(), h, true)));
    plain.push_back(cond(scheme.newton_matrix(0.0, y.data(), h, false)));
    std::cout << "[ cond     ] " << (kIndex2 ? "index 2" : "index 3") << " h = " << h << ": scaled " << scaled.back()
              << ", unscaled " << plain.back() << "\n";
  }
  const double slope_scaled = log_slope(hs, scaled), slope_plain = log_slope(hs, plain);
  std::cout << "[ cond     ] slopes d log(cond) / d log(h): scaled " << slope_scaled << ", unscaled " << slope_plain
            << "\n";
  // Bounded with the scaling: within a factor 2 over four decades of h.
  EXPECT_LT(*std::max_element(scaled.begin(), scaled.end()), 2 * *std::min_element(scaled.begin(), scaled.end()));
  EXPECT_LT(std::abs(slope_scaled), 0.05);
  // Without it, it grows at least like h^-2: the slopes differ by more than 40x.
  EXPECT_LE(slope_plain, -1.9);
  EXPECT_GT(std::abs(slope_plain), 40 * std::abs(slope_scaled));
}

TEST(GeneralizedAlphaConditioning, ScaledBoundedUnscaledGrowsIndex3) { expect_scaled_condition_bounded<false>(); }
TEST(GeneralizedAlphaConditioning, ScaledBoundedUnscaledGrowsIndex2) { expect_scaled_condition_bounded<true>(); }

}  // namespace
}  // namespace cstab

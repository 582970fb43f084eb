// core/jet.hpp: each elementary function's first and second derivative
// against its closed form, the arithmetic against the product and quotient
// rules written out, and a jet under a dual (ad::Dual<K, Jet>, as the
// index-1 Jacobians use it) against a mixed third derivative by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/jet.hpp"

namespace cstab::ad {
namespace {

// The jet of x0 + s: value x0, slope 1, no curvature.
Jet line(double x0) { return {x0, 1, 0}; }

void expect_jet(const Jet& j, double f, double d1, double d2, const std::string& what) {
  EXPECT_NEAR(j.f0, f, 1e-14 * (1 + std::abs(f))) << what;
  EXPECT_NEAR(j.f1, d1, 1e-13 * (1 + std::abs(d1))) << what;
  EXPECT_NEAR(j.f2, d2, 1e-12 * (1 + std::abs(d2))) << what;
}

TEST(Jet, ElementaryFunctionsMatchClosedForms) {
  for (double x : {0.3, 0.7, -0.45}) {
    expect_jet(sin(line(x)), std::sin(x), std::cos(x), -std::sin(x), "sin");
    expect_jet(cos(line(x)), std::cos(x), -std::sin(x), -std::cos(x), "cos");
    const double c = std::cos(x);
    expect_jet(tan(line(x)), std::tan(x), 1 / (c * c), 2 * std::sin(x) / (c * c * c), "tan");
    expect_jet(exp(line(x)), std::exp(x), std::exp(x), std::exp(x), "exp");
    expect_jet(asin(line(x)), std::asin(x), 1 / std::sqrt(1 - x * x), x / std::pow(1 - x * x, 1.5), "asin");
    expect_jet(acos(line(x)), std::acos(x), -1 / std::sqrt(1 - x * x), -x / std::pow(1 - x * x, 1.5), "acos");
    expect_jet(atan(line(x)), std::atan(x), 1 / (1 + x * x), -2 * x / ((1 + x * x) * (1 + x * x)), "atan");
    const double ch = std::cosh(x);
    expect_jet(tanh(line(x)), std::tanh(x), 1 / (ch * ch), -2 * std::sinh(x) / (ch * ch * ch), "tanh");
    expect_jet(sinh(line(x)), std::sinh(x), std::cosh(x), std::sinh(x), "sinh");
    expect_jet(cosh(line(x)), std::cosh(x), std::sinh(x), std::cosh(x), "cosh");
    // x^3 at any sign, and x^-2.
    expect_jet(pow(line(x), 3.0), x * x * x, 3 * x * x, 6 * x, "pow 3");
    expect_jet(pow(line(x), -2.0), 1 / (x * x), -2 / (x * x * x), 6 / (x * x * x * x), "pow -2");
  }
  for (double x : {0.3, 2.5}) {
    expect_jet(log(line(x)), std::log(x), 1 / x, -1 / (x * x), "log");
    expect_jet(sqrt(line(x)), std::sqrt(x), 0.5 / std::sqrt(x), -0.25 / std::pow(x, 1.5), "sqrt");
    // x^s for a variable exponent: d/ds x^(p + s) = x^p ln x, then x^p ln^2 x.
    const Jet p{1.5, 1, 0};
    expect_jet(pow(Jet(x), p), std::pow(x, 1.5), std::pow(x, 1.5) * std::log(x),
               std::pow(x, 1.5) * std::log(x) * std::log(x), "pow variable exponent");
  }
}

TEST(Jet, Atan2InEveryQuadrant) {
  // The angle of (cos(w s + a), sin(w s + a)) scaled by r(s) = 2 + s:
  // theta = w s + a, so theta' = w and theta'' = 0 whatever the quadrant.
  const double w = 1.7;
  for (double a : {0.4, 2.0, -2.5, -0.9}) {
    const Jet r{2, 1, 0}, phase{a, w, 0};
    const Jet theta = atan2(r * sin(phase), r * cos(phase));
    expect_jet(theta, a, w, 0, "atan2 at angle " + std::to_string(a));
  }
}

TEST(Jet, ArithmeticFollowsProductAndQuotientRules) {
  // u = 1 + 2s + 3s^2/2 (u'' = 3), v = 2 - s + s^2 (v'' = 2) at s = 0.
  const Jet u{1, 2, 3}, v{2, -1, 2};
  expect_jet(u * v, 2, 2 * 2 + 1 * -1, 3 * 2 + 2 * 2 * -1 + 1 * 2, "product");
  // (u/v)' = (u'v - uv')/v^2, (u/v)'' by hand: (u''v - uv'')/v^2 - 2 v'(u'v - uv')/v^3.
  const double q1 = (2 * 2 - 1 * -1) / 4.0;
  const double q2 = (3 * 2 - 1 * 2) / 4.0 - 2 * -1 * (2 * 2 - 1 * -1) / 8.0;
  expect_jet(u / v, 0.5, q1, q2, "quotient");
  expect_jet(2.0 * u - v + 1.0, 1, 5, 4, "with constants");
}

TEST(Jet, UnderADualGivesMixedThirdDerivatives) {
  // f(x, y) = sin(x) y^2 along (x, y)(s) = (x0 + s vx + s^2 ax / 2, y0 + s vy):
  // d^2 f / ds^2 at s = 0, and its derivatives in x0 and vx, by hand.
  using D = Dual<2, Jet>;
  using Der = Eigen::Matrix<Jet, 2, 1>;
  const double x0 = 0.6, y0 = 1.3, vx = 0.8, vy = -0.5, ax = 0.4;
  Der dx = Der::Zero(), dy = Der::Zero();
  dx(0) = Jet(1, 0, 0);  // d/dx0 moves the value
  dx(1) = Jet(0, 1, 0);  // d/dvx moves the slope
  const D x(Jet(x0, vx, ax), dx), y(Jet(y0, vy, 0), dy);
  const D f = sin(x) * y * y;
  // f'' = (-sin x vx^2 + cos x ax) y^2 + 4 cos x vx y vy + 2 sin x vy^2
  auto second = [&](double x0_, double vx_) {
    return (-std::sin(x0_) * vx_ * vx_ + std::cos(x0_) * ax) * y0 * y0 + 4 * std::cos(x0_) * vx_ * y0 * vy +
           2 * std::sin(x0_) * vy * vy;
  };
  EXPECT_NEAR(f.value().f2, second(x0, vx), 1e-13);
  const double d_x0 =
      (-std::cos(x0) * vx * vx - std::sin(x0) * ax) * y0 * y0 - 4 * std::sin(x0) * vx * y0 * vy + 2 * std::cos(x0) * vy * vy;
  const double d_vx = -2 * std::sin(x0) * vx * y0 * y0 + 4 * std::cos(x0) * y0 * vy;
  EXPECT_NEAR(f.derivatives()(0).f2, d_x0, 1e-13);
  EXPECT_NEAR(f.derivatives()(1).f2, d_vx, 1e-13);
}

}  // namespace
}  // namespace cstab::ad

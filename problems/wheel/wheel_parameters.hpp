// The wheel's parameters (problems/wheel/wheel.hpp: the paper's values)
// and the design of its near-singular variant wheel-sharp
// (problems/wheel/wheel_sharp.hpp), apart from the models so that code which
// only needs the numbers (the stress tests) does not compile the wheel.
#pragma once

#include <array>

namespace cstab {

struct WheelParameters {
  double M = 1.0;                 // wheel (hoop) mass
  double m = 0.5;                 // pendulum point mass
  double r = 7.0 / 40.0;          // wheel radius
  double l = 0.8 * 7.0 / 40.0;    // pendulum length
  double g = 9.81;
  // p(x) = c4 x^4 + c3 x^3 + c2 x^2 + c1 x + c0
  std::array<double, 5> curve = {0.5, -0.13, -0.5, 0.13, 1.0};  // c0..c4
  // Initial data (NOTES.md): contact abscissa, centre's horizontal velocity,
  // pendulum angle and rate.
  double contact_x0 = 0.5, xdot0 = 1.05, phi0 = 3.4, phidot0 = -11.5;

  template <class S>
  S p(const S& x) const {
    return (((curve[4] * x + curve[3]) * x + curve[2]) * x + curve[1]) * x + curve[0];
  }
  template <class S>
  S dp(const S& x) const {
    return ((4 * curve[4] * x + 3 * curve[3]) * x + 2 * curve[2]) * x + curve[1];
  }
  template <class S>
  S ddp(const S& x) const {
    return (12 * curve[4] * x + 6 * curve[3]) * x + 2 * curve[2];
  }
};

struct WheelSharpDesign {
  static constexpr double kSharpness = 0.97;  // r * kappa_max
  // max over x of kappa(x) = p''(x) / (1 + p'(x)^2)^(3/2) for the wheel's curve.
  static double max_curvature(const WheelParameters& p, double* at = nullptr);
  static WheelParameters parameters();
};

}  // namespace cstab

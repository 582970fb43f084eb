#include "problems/wheel/wheel_sharp.hpp"

#include <cmath>

#include "core/format.hpp"

namespace cstab {

double WheelSharpDesign::max_curvature(const WheelParameters& p, double* at) {
  auto kappa = [&](double x) {
    const double d1 = p.dp(x);
    return p.ddp(x) / std::pow(1 + d1 * d1, 1.5);
  };
  // Grid over [-2, 2] (the curve flattens beyond: kappa ~ 1/x^7), then a
  // golden-section refinement around the best grid point.
  double best_x = 0, best = kappa(0);
  for (int i = -4000; i <= 4000; ++i) {
    const double x = i * 5e-4;
    if (kappa(x) > best) best = kappa(best_x = x);
  }
  double a = best_x - 5e-4, b = best_x + 5e-4;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 60; ++it) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (kappa(c) > kappa(d))
      b = d;  // the maximum lies in [a, d]
    else
      a = c;
  }
  if (at) *at = (a + b) / 2;
  return kappa((a + b) / 2);
}

WheelParameters WheelSharpDesign::parameters() {
  WheelParameters p;
  p.r = kSharpness / max_curvature(p);
  p.l = 0.8 * p.r;
  return p;
}

Wheel make_wheel_sharp() {
  const WheelParameters p = WheelSharpDesign::parameters();
  return Wheel(p, "wheel-sharp",
               "the wheel with r = " + format_short(p.r) + " = " + format_short(WheelSharpDesign::kSharpness) +
                   " / kappa_max of the curve (l = 0.8 r): near-singular reaction matrix where the wheel "
                   "rolls through the curve's sharpest point",
               // The contact point runs 1/sigma ~ 33 times faster than the centre:
               // h = 1e-3 does not resolve it (0.45 off at t = 5 with RK4, measured), 2e-4 does.
               2e-4);
}

}  // namespace cstab

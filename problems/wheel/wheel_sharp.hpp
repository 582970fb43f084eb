// The wheel of Pesterev et al. made near-singular (stress tests): the same
// curve, hoop, pendulum and initial data, but the wheel's radius r is chosen
// so that r times the curve's largest curvature kappa_max (about 3.434, at
// x = 0.619, in the right-hand valley the wheel rolls through) is
// kSharpness = 0.97; the pendulum keeps l = 0.8 r. The centre's path is the
// offset curve c(s) = (s, p) + r n(s) with c'(s) = sigma (1, p'),
// sigma = 1 - r kappa(s): at sigma -> 0 the offset curve has a cusp, the
// contact point races along the curve (ds/dt = centre speed / (sigma w)), and
// the reaction matrix A(X) of the state-space form becomes singular. At
// kSharpness = 0.97 the wheel passes within sigma = 0.03 of that.
#pragma once

#include "problems/wheel/wheel.hpp"
#include "problems/wheel/wheel_parameters.hpp"

namespace cstab {

// The "wheel-sharp" problem: a Wheel with the design's parameters, so it
// reuses every instantiation of the wheel.
Wheel make_wheel_sharp();

}  // namespace cstab

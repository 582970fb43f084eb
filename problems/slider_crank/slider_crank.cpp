#include "problems/slider_crank/slider_crank.hpp"

namespace cstab {

void SliderCrankMechanical::initial_state(Vec<double, 3>& q, Vec<double, 3>& v) const {
  // As setIC() of the example: q = pi/2, p = asin(-a), x = cos p (the term
  // a cos q of Phi1 is the round-off of cos(pi/2)).
  const double pi = 4 * std::atan(1.0);
  q(qQ) = pi / 2;
  q(qP) = std::asin(-p_.a);
  q(qX) = std::cos(q(qP));
  v.setZero();
}

// ---------------------------------------------------------------------------
// Minimal coordinate theta (the crank angle). On the constraint manifold
//   sin p = -a sin theta, cos p = sqrt(1 - a^2 sin^2 theta) > 0 (|a| < 1),
//   p(theta) = -asin(a sin theta),  x(theta) = cos p + a cos theta.
// Differentiating cos p p' = -a cos theta:
//   p'  = -a cos theta / cos p,
//   p'' = (a sin theta + sin p p'^2) / cos p,
//   x'  = -sin p p' - a sin theta,
//   x'' = -cos p p'^2 - sin p p'' - a cos theta.
// Kinetic energy T = m(theta) theta'^2 / 2, m = J1 + m2 x'^2 + J2 p'^2, so
//   m theta'' + (m2 x' x'' + J2 p' p'') theta'^2 = Q_theta.
// Generalized force: the spring-damper joins the crank midpoint
//   A = (a/2)(cos theta, sin theta) and the rod point B = (x - cos p / 2, -sin p / 2);
// with d = B - A, l = |d|, l_theta = d . (B' - A') / l,
//   Q_theta = -(k (l - l0) + c l_theta theta') l_theta + F (x' - sin p p')
// (F does the work F d(x + cos p)).
// ---------------------------------------------------------------------------
namespace {

struct CrankGeometry {
  double s1, c1, s2, c2, p, x, dp, ddp, dx, ddx;
};

CrankGeometry crank_geometry(const SliderCrankParameters& prm, double theta) {
  CrankGeometry g;
  const double a = prm.a;
  g.s1 = std::sin(theta);
  g.c1 = std::cos(theta);
  g.s2 = -a * g.s1;
  g.c2 = std::sqrt(1 - g.s2 * g.s2);
  g.p = std::asin(g.s2);
  g.x = g.c2 + a * g.c1;
  g.dp = -a * g.c1 / g.c2;
  g.ddp = (a * g.s1 + g.s2 * g.dp * g.dp) / g.c2;
  g.dx = -g.s2 * g.dp - a * g.s1;
  g.ddx = -g.c2 * g.dp * g.dp - g.s2 * g.ddp - a * g.c1;
  return g;
}

}  // namespace

void SliderCrankMinimal::initial_state(Vec<double, 2>& y0) const {
  y0(0) = 2 * std::atan(1.0);
  y0(1) = 0;
}

bool SliderCrankMinimal::rhs(double, const Vec<double, 2>& y, Vec<double, 2>& dy) const {
  const auto g = crank_geometry(p_, y(0));
  const double a = p_.a, w = y(1);
  const double dxA = g.x - g.c2 / 2 - a * g.c1 / 2;
  const double dyA = -g.s2 / 2 - a * g.s1 / 2;
  const double dxB = g.dx + g.s2 * g.dp / 2 + a * g.s1 / 2;  // d/dtheta of dxA
  const double dyB = -g.c2 * g.dp / 2 - a * g.c1 / 2;        // d/dtheta of dyA
  const double l = std::hypot(dxA, dyA);
  const double l_theta = (dxA * dxB + dyA * dyB) / l;
  const double Q = -(p_.k * (l - p_.l0) + p_.c * l_theta * w) * l_theta + p_.F * (g.dx - g.s2 * g.dp);
  const double m = p_.J1 + p_.m2 * g.dx * g.dx + p_.J2 * g.dp * g.dp;
  const double half_dm = p_.m2 * g.dx * g.ddx + p_.J2 * g.dp * g.ddp;
  dy(0) = w;
  dy(1) = (Q - half_dm * w * w) / m;
  return true;
}

void SliderCrankMinimal::to_canonical(double, const Vec<double, 2>& y, double* c) const {
  const auto g = crank_geometry(p_, y(0));
  c[kScQ] = y(0);
  c[kScX] = g.x;
  c[kScP] = g.p;
  c[kScQd] = y(1);
  c[kScXd] = g.dx * y(1);
  c[kScPd] = g.dp * y(1);
}

void SliderCrankMinimal::residuals(double t, const Vec<double, 2>& y, double* out) const {
  double c[6];
  to_canonical(t, y, c);
  Vec<double, 2> phi;
  mech_.holonomic(t, Vec<double, 3>(c[0], c[1], c[2]), phi);
  out[0] = phi(0);
  out[1] = phi(1);
}

// ---------------------------------------------------------------------------

ProblemInfo SliderCrank::info() const {
  ProblemInfo info;
  info.name = "slider-crank";
  info.description =
      "slider-crank of the SUNDIALS IDAS example idasSlCrank_dns: crank, rod and slider under a "
      "spring-damper and a constant horizontal force (forced and damped: no energy law)";
  info.coordinates = {"q", "x", "p", "qdot", "xdot", "pdot"};
  info.formulations = {
      {"mechanical", "the example's q = (crank angle q, slider x, rod angle p), M = diag(J1, m2, J2), 2 joint constraints",
       SliderCrankMechanical::constraints()},
      {"minimal", "Lagrange equation in the crank angle (1 degree of freedom); x, p from the constraints",
       SliderCrankMechanical::constraints()},
  };
  info.has_energy = false;
  info.default_t_end = 10;
  info.reference_time = 10;
  info.reference_description =
      "minimal-coordinate ODE (crank angle), GSL rk8pd, rtol = atol = 1e-13; the example prints "
      "y1 = 1.2757, y2 = 1.0236, y3 = -0.49881 at t = 10";
  return info;
}

bool SliderCrank::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

}  // namespace cstab

#include "problems/wheel/wheel.hpp"

#include "core/autodiff.hpp"

namespace cstab {

std::vector<ConstraintInfo> WheelStateSpace::constraints() {
  return {
      {"contact", "holonomic (r=2)", "f1 = h(x_a, z_a): the contact point lies on the curve (eq. 18)"},
      {"rolling", "non-holonomic (r=1)", "f2 = -xdot sin(alpha) + zdot cos(alpha) + r thetadot: no slip (eq. 19)"},
      {"tangency", "holonomic (r=1, alpha' = U)", "f3 = h_x sin(alpha) - h_z cos(alpha): wheel tangent to the curve (eq. 20)"},
  };
}

void WheelStateSpace::initial_state(Vec<double, kStates>& X0) const {
  // alpha from tangency with sin(alpha) < 0: the centre-to-contact direction
  // mu = (cos a, sin a) is the downward unit normal -(-p', 1)/w.
  const double xa = p_.contact_x0;
  const double slope = p_.dp(xa);
  const double w = std::sqrt(1 + slope * slope);
  const double ca = slope / w, sa = -1 / w;
  X0.setZero();
  X0(iALPHA) = std::atan2(sa, ca);
  X0(iX) = xa - p_.r * ca;
  X0(iZ) = p_.p(xa) - p_.r * sa;
  // The centre moves parallel to the tangent (1, p'(x_a)).
  X0(iXD) = p_.xdot0;
  X0(iZD) = p_.xdot0 * slope;
  // Rolling (19) gives thetadot.
  X0(iTHD) = (X0(iXD) * sa - X0(iZD) * ca) / p_.r;
  X0(iTH) = 0;
  X0(iPHI) = p_.phi0;
  X0(iPHID) = p_.phidot0;
}

// ---------------------------------------------------------------------------
// Minimal coordinates q = (s, phi). Geometry of the centre's path, with
// w = sqrt(1 + p'^2), kappa = p'' / w^3 (signed curvature), sigma = 1 - r kappa:
//   centre c(s) = (s, p) + r (-p', 1) / w,   c'(s) = sigma (1, p')
//   rolling:   thetadot = -(sigma w / r) sdot   (from (19) with mu = -(-p',1)/w)
// Lagrangian L = T - V:
//   T = 1/2 (2M + m) sigma^2 w^2 sdot^2 + m l sigma (cos phi + p' sin phi) sdot phidot + 1/2 m l^2 phidot^2
//   V = (M + m) g (p + r / w) - m g l cos phi
// (the hoop's rotational energy 1/2 M r^2 thetadot^2 equals its translational
// 1/2 M |c'|^2 sdot^2). Lagrange's equations M(q) q'' = -C(q, q') - grad V
// with C_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) q'_j q'_k; the partial
// derivatives of M and V come from forward-mode AD.
// ---------------------------------------------------------------------------
namespace {

template <class T>
void minimal_mass_and_potential(const WheelParameters& p, const T& s, const T& phi,
                                Eigen::Matrix<T, 2, 2>& M, T& V) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T d1 = p.dp(s), d2 = p.ddp(s);
  const T w = sqrt(1.0 + d1 * d1);
  const T sigma = 1.0 - p.r * d2 / (w * w * w);
  M(0, 0) = (2 * p.M + p.m) * sigma * sigma * w * w;
  M(0, 1) = p.m * p.l * sigma * (cos(phi) + d1 * sin(phi));
  M(1, 0) = M(0, 1);
  M(1, 1) = T(p.m * p.l * p.l);
  V = (p.M + p.m) * p.g * (p.p(s) + p.r / w) - p.m * p.g * p.l * cos(phi);
}

struct CentreGeometry {
  double cx, cz, sigma, slope, w;
};

CentreGeometry centre_geometry(const WheelParameters& p, double s) {
  const double d1 = p.dp(s), d2 = p.ddp(s);
  const double w = std::sqrt(1 + d1 * d1);
  return {s - p.r * d1 / w, p.p(s) + p.r / w, 1 - p.r * d2 / (w * w * w), d1, w};
}

}  // namespace

void WheelMinimal::initial_state(Vec<double, kStates>& y0) const {
  const auto g = centre_geometry(p_, p_.contact_x0);
  y0(iS) = p_.contact_x0;
  y0(iSD) = p_.xdot0 / g.sigma;  // xdot = sigma sdot
  y0(iPHI) = p_.phi0;
  y0(iPHID) = p_.phidot0;
  y0(iTH) = 0;
}

bool WheelMinimal::rhs(double, const Vec<double, kStates>& y, Vec<double, kStates>& dy) const {
  using D = ad::Dual<2>;
  const D s(y(iS), 2, 0), phi(y(iPHI), 2, 1);
  Eigen::Matrix<D, 2, 2> Md;
  D V;
  minimal_mass_and_potential(p_, s, phi, Md, V);
  Eigen::Matrix2d M;
  std::array<Eigen::Matrix2d, 2> dM;  // dM[k] = dM/dq_k
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      M(i, j) = Md(i, j).value();
      dM[0](i, j) = Md(i, j).derivatives()(0);
      dM[1](i, j) = Md(i, j).derivatives()(1);
    }
  const Eigen::Vector2d qd(y(iSD), y(iPHID));
  Eigen::Vector2d rhs = -V.derivatives();
  for (int i = 0; i < 2; ++i) {
    double c = 0;
    for (int k = 0; k < 2; ++k) c += (dM[k].row(i).dot(qd)) * qd(k);  // sum_jk dM_ij/dq_k qd_j qd_k
    c -= 0.5 * qd.dot(dM[i] * qd);
    rhs(i) -= c;
  }
  const Eigen::Vector2d qdd = M.ldlt().solve(rhs);
  const auto g = centre_geometry(p_, y(iS));
  dy(iS) = y(iSD);
  dy(iSD) = qdd(0);
  dy(iPHI) = y(iPHID);
  dy(iPHID) = qdd(1);
  dy(iTH) = -(g.sigma * g.w / p_.r) * y(iSD);
  return true;
}

void WheelMinimal::to_canonical(double, const Vec<double, kStates>& y, double* c) const {
  const auto g = centre_geometry(p_, y(iS));
  using W = WheelStateSpace;
  c[W::iX] = g.cx;
  c[W::iXD] = g.sigma * y(iSD);
  c[W::iZ] = g.cz;
  c[W::iZD] = g.sigma * g.slope * y(iSD);
  c[W::iTH] = y(iTH);
  c[W::iTHD] = -(g.sigma * g.w / p_.r) * y(iSD);
  c[W::iPHI] = y(iPHI);
  c[W::iPHID] = y(iPHID);
  c[W::iALPHA] = std::atan2(-1 / g.w, g.slope / g.w);
}

void WheelMinimal::residuals(double t, const Vec<double, kStates>& y, double* out) const {
  Vec<double, WheelStateSpace::kStates> X;
  to_canonical(t, y, X.data());
  Vec<double, 3> f;
  ss_.outputs(t, X, f);
  for (int i = 0; i < 3; ++i) out[i] = f(i);
}

double WheelMinimal::energy(const Vec<double, kStates>& y) const {
  Eigen::Matrix2d M;
  double V;
  minimal_mass_and_potential(p_, y(iS), y(iPHI), M, V);
  const Eigen::Vector2d qd(y(iSD), y(iPHID));
  return 0.5 * qd.dot(M * qd) + V;
}

void WheelMechanical::initial_state(Vec<double, 4>& q, Vec<double, 4>& v) const {
  Vec<double, WheelStateSpace::kStates> X;
  ss_.initial_state(X);
  using W = WheelStateSpace;
  q << X(W::iX), X(W::iZ), X(W::iTH), X(W::iPHI);
  v << X(W::iXD), X(W::iZD), X(W::iTHD), X(W::iPHID);
}

void WheelMechanical::to_canonical(double, const Vec<double, 4>& q, const Vec<double, 4>& v, double* c) const {
  using W = WheelStateSpace;
  const double s = contact(q(qX), q(qZ));
  const double d1 = p_.dp(s), w = std::sqrt(1 + d1 * d1);
  c[W::iX] = q(qX);
  c[W::iXD] = v(qX);
  c[W::iZ] = q(qZ);
  c[W::iZD] = v(qZ);
  c[W::iTH] = q(qTH);
  c[W::iTHD] = v(qTH);
  c[W::iPHI] = q(qPHI);
  c[W::iPHID] = v(qPHI);
  c[W::iALPHA] = std::atan2(-1 / w, d1 / w);
}

// ---------------------------------------------------------------------------

ProblemInfo Wheel::info() const {
  ProblemInfo info;
  info.name = name_.empty() ? "wheel" : name_;
  info.description =
      !description_.empty() ? description_
                            : "heavy hoop with a pendulum rolling without slip on z = x^4 + 0.13x^3 - 0.5x^2 - "
                              "0.13x + 0.5 (Pesterev-Matrosov-Morozov; curve and g = 9.81 per NOTES.md)";
  info.resolution_step = resolution_step_;
  info.coordinates = {"x", "xdot", "z", "zdot", "theta", "thetadot", "phi", "phidot", "alpha"};
  info.formulations = {
      {"state-space", "the paper's affine form, 9 states, reactions [R_x, R_z, U]",
       WheelStateSpace::constraints()},
      {"minimal", "Lagrange equations in (s, phi), theta from rolling; no constraints to drift",
       WheelStateSpace::constraints()},
      {"mechanical", "q = (x, z, theta, phi) with M, Q; distance-to-curve + rolling constraints",
       WheelMechanical(params_).constraints()},
  };
  info.has_energy = true;
  info.default_t_end = 200;
  info.reference_time = 5;
  info.reference_description = "minimal-coordinate ODE, GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

double Wheel::energy(double, const double* c) const {
  using W = WheelStateSpace;
  const auto& p = params_;
  const double xd = c[W::iXD], zd = c[W::iZD], thd = c[W::iTHD], phi = c[W::iPHI], phid = c[W::iPHID];
  const double vx = xd + p.l * phid * std::cos(phi), vz = zd + p.l * phid * std::sin(phi);
  const double T = 0.5 * p.M * (xd * xd + zd * zd + p.r * p.r * thd * thd) + 0.5 * p.m * (vx * vx + vz * vz);
  const double V = p.M * p.g * c[W::iZ] + p.m * p.g * (c[W::iZ] - p.l * std::cos(phi));
  return T + V;
}

bool Wheel::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

}  // namespace cstab

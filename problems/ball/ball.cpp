#include "problems/ball/ball.hpp"

namespace cstab {

namespace {

// omega(0) = omega_rho e_rho + ((R - r) cos(alpha)/r) beta' e_alpha - ((R - r)/r) alpha' e_beta
// (NOTES.md; the transcription prints e_2 for e_alpha). It gives
// omega x (r e_rho) = -rho alpha' e_alpha - rho cos(alpha) beta' e_beta = -v_C:
// the contact point is at rest.
Eigen::Vector3d initial_omega(const BallParameters& p) {
  ball_detail::V3<double> er, ea, eb;
  ball_detail::basis(p.alpha0, p.beta0, er, ea, eb);
  return p.omega_rho0 * er + (p.rc() * std::cos(p.alpha0) / p.r) * p.betadot0 * ea -
         (p.rc() / p.r) * p.alphadot0 * eb;
}

}  // namespace

std::vector<ConstraintInfo> BallMechanical::constraints() {
  return {
      {"radius", "holonomic", "rho - (R - r): the ball touches the bowl"},
      {"orth11", "holonomic", "e1.e1 - 1"},
      {"orth12", "holonomic", "e1.e2"},
      {"orth13", "holonomic", "e1.e3"},
      {"orth22", "holonomic", "e2.e2 - 1"},
      {"orth23", "holonomic", "e2.e3"},
      {"orth33", "holonomic", "e3.e3 - 1"},
      {"roll_alpha", "non-holonomic", "e_alpha . v_P: no slip along e_alpha"},
      {"roll_beta", "non-holonomic", "e_beta . v_P: no slip along e_beta"},
  };
}

void BallMechanical::initial_state(Vec<double, 12>& q, Vec<double, 12>& v) const {
  q.setZero();
  v.setZero();
  q(qRHO) = p_.rc();
  q(qALPHA) = p_.alpha0;
  q(qBETA) = p_.beta0;
  q(qE1) = q(qE2 + 1) = q(qE3 + 2) = 1.0;  // e_i(0) = the fixed axes
  v(qRHO) = 0;
  v(qALPHA) = p_.alphadot0;
  v(qBETA) = p_.betadot0;
  const Eigen::Vector3d w = initial_omega(p_);
  for (int i = 0; i < 3; ++i) v.segment<3>(3 + 3 * i) = w.cross(Eigen::Vector3d::Unit(i));
}

// ---------------------------------------------------------------------------
// Newton-Euler. Contact normal n = c/|c| (bowl centre -> ball centre), the
// contact point P = c + r n. With F the contact force at P:
//   m a_C = m g_vec + F,   I omega' = (r n) x F          (sphere: no gyroscopic term)
//   rolling v_C + omega x (r n) = 0   =>   v_C = r n x omega
// (so v_C is tangent and |c| stays R - r). Differentiating the rolling
// condition, a_C = r n' x omega + r n x omega' with n' = v_C / |c|; with
// F = m a_C - m g_vec,
//   I omega' = m r^2 n x (n' x omega) + m r^2 (n (n.omega') - omega') - m r n x g_vec.
// Its n-component gives I n.omega' = 0, hence
//   omega' = [m r^2 n x (n' x omega) - m r n x g_vec] / (I + m r^2),
// a closed ODE in (n, omega). The orientation follows R' = [omega]_x R, i.e.
// quat' = 1/2 (0, omega) * quat. The direction is carried unnormalized as u
// with u' = |u| n' (so n' is exact and |u| is invariant), and the azimuth
// beta' = (c_x v_y - c_y v_x) / (c_x^2 + c_y^2) only unwraps atan2.
// ---------------------------------------------------------------------------

void BallNewtonEuler::initial_state(Vec<double, kStates>& y) const {
  ball_detail::V3<double> er, ea, eb;
  ball_detail::basis(p_.alpha0, p_.beta0, er, ea, eb);
  y.setZero();
  y.segment<3>(iU) = er;
  y.segment<3>(iW) = initial_omega(p_);
  y(iQ) = 1.0;  // identity: e_i(0) = the fixed axes
  y(iBETA) = p_.beta0;
}

bool BallNewtonEuler::rhs(double, const Vec<double, kStates>& y, Vec<double, kStates>& dy) const {
  const Eigen::Vector3d u = y.segment<3>(iU);
  const double nu = u.norm();
  const Eigen::Vector3d n = u / nu;
  const Eigen::Vector3d w = y.segment<3>(iW);
  const double m = p_.m, r = p_.r, rc = p_.rc();
  const Eigen::Vector3d vc = r * n.cross(w);
  const Eigen::Vector3d nd = vc / rc;
  const Eigen::Vector3d gvec(0, 0, -p_.g);
  dy.segment<3>(iU) = nu * nd;
  dy.segment<3>(iW) = (m * r * r * n.cross(nd.cross(w)) - m * r * n.cross(gvec)) / (p_.inertia() + m * r * r);
  const double q0 = y(iQ);
  const Eigen::Vector3d qv = y.segment<3>(iQ + 1);
  dy(iQ) = -0.5 * w.dot(qv);
  dy.segment<3>(iQ + 1) = 0.5 * (q0 * w + w.cross(qv));
  const Eigen::Vector3d c = rc * n;
  dy(iBETA) = (c(0) * vc(1) - c(1) * vc(0)) / (c(0) * c(0) + c(1) * c(1));
  return true;
}

void BallNewtonEuler::to_canonical(double, const Vec<double, kStates>& y, double* c) const {
  const Eigen::Vector3d n = y.segment<3>(iU).normalized();
  const Eigen::Vector3d w = y.segment<3>(iW);
  const double rc = p_.rc();
  // Spherical angles of n: cos(alpha) = |n_xy| > 0, sin(alpha) = -n_z.
  const double ca = std::hypot(n(0), n(1)), sa = -n(2);
  const double alpha = std::atan2(sa, ca);
  const double beta_wrapped = std::atan2(n(1), n(0));
  const double beta = y(iBETA) + std::remainder(beta_wrapped - y(iBETA), 2 * std::numbers::pi);
  // Rotation matrix of the normalized quaternion; e_i = its columns.
  Eigen::Quaterniond quat(y(iQ), y(iQ + 1), y(iQ + 2), y(iQ + 3));
  quat.normalize();
  const Eigen::Matrix3d Rm = quat.toRotationMatrix();
  ball_detail::V3<double> er, ea, eb;
  ball_detail::basis(alpha, beta, er, ea, eb);
  const Eigen::Vector3d vc = p_.r * er.cross(w);
  c[0] = rc;
  c[1] = alpha;
  c[2] = beta;
  for (int i = 0; i < 3; ++i)
    for (int d = 0; d < 3; ++d) c[3 + 3 * i + d] = Rm(d, i);
  c[12] = er.dot(vc);
  c[13] = ea.dot(vc) / rc;
  c[14] = eb.dot(vc) / (rc * ca);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d ed = w.cross(Eigen::Vector3d(Rm.col(i)));
    for (int d = 0; d < 3; ++d) c[15 + 3 * i + d] = ed(d);
  }
}

void BallNewtonEuler::residuals(double t, const Vec<double, kStates>& y, double* out) const {
  Vec<double, 24> c;
  to_canonical(t, y, c.data());
  const Vec<double, 12> q = c.head<12>(), v = c.tail<12>();
  Vec<double, 7> phi;
  Vec<double, 2> psi;
  mech_.holonomic(t, q, phi);
  mech_.nonholonomic(t, q, v, psi);
  for (int i = 0; i < 7; ++i) out[i] = phi(i);
  for (int i = 0; i < 2; ++i) out[7 + i] = psi(i);
}

double BallNewtonEuler::energy(const Vec<double, kStates>& y) const {
  const Eigen::Vector3d n = y.segment<3>(iU).normalized();
  const Eigen::Vector3d w = y.segment<3>(iW);
  const Eigen::Vector3d vc = p_.r * n.cross(w);
  const double z = p_.rc() * n(2);
  return 0.5 * p_.m * vc.squaredNorm() + 0.5 * p_.inertia() * w.squaredNorm() + p_.m * p_.g * z;
}

// ---------------------------------------------------------------------------

ProblemInfo Ball::info() const {
  ProblemInfo info;
  info.name = "ball";
  info.description =
      "solid ball (m = 1, r = 1) rolling without slip in a spherical bowl (R = 8), g = 9.81 "
      "(Braun-Goldfarb Part II, Sec. 3.1; constraints and initial data per NOTES.md)";
  info.coordinates = {"rho", "alpha", "beta"};
  for (int i = 1; i <= 3; ++i)
    for (const char* d : {"x", "y", "z"}) info.coordinates.push_back("e" + std::to_string(i) + d);
  info.coordinates.insert(info.coordinates.end(), {"rhodot", "alphadot", "betadot"});
  for (int i = 1; i <= 3; ++i)
    for (const char* d : {"x", "y", "z"}) info.coordinates.push_back("e" + std::to_string(i) + d + "dot");
  info.formulations = {
      {"mechanical",
       "q = [rho, alpha, beta, e1, e2, e3] (12): M = diag(m, m rho^2, m rho^2 cos^2 alpha, I/2 x 9), "
       "7 holonomic + 2 rolling constraints",
       BallMechanical::constraints()},
      {"newton-euler",
       "rigid body with the contact force eliminated: centre direction, omega, unit quaternion; "
       "constraints hold by construction",
       BallMechanical::constraints()},
  };
  info.has_energy = true;
  info.first_integrals = {"spin", "eps"};
  info.default_t_end = 100;
  info.reference_time = 10;
  info.reference_description = "Newton-Euler ODE, GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

double Ball::energy(double, const double* c) const {
  const auto& p = params_;
  const double rho = c[0], ca = std::cos(c[1]);
  const double rd = c[12], ad = c[13], bd = c[14];
  double rot = 0;
  for (int i = 15; i < 24; ++i) rot += c[i] * c[i];
  return 0.5 * p.m * (rd * rd + rho * rho * (ad * ad + ca * ca * bd * bd)) + 0.25 * p.inertia() * rot -
         p.m * p.g * rho * std::sin(c[1]);
}

Eigen::Vector3d Ball::centre(const double* c) {
  ball_detail::V3<double> er, ea, eb;
  ball_detail::basis(c[1], c[2], er, ea, eb);
  return c[0] * er;
}

Eigen::Vector3d Ball::angular_velocity(const double* c) {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e(c[3 + 3 * i], c[4 + 3 * i], c[5 + 3 * i]);
    const Eigen::Vector3d ed(c[15 + 3 * i], c[16 + 3 * i], c[17 + 3 * i]);
    w += 0.5 * e.cross(ed);
  }
  return w;
}

void Ball::first_integrals(double, const double* c, double* out) const {
  ball_detail::V3<double> er, ea, eb;
  ball_detail::basis(c[1], c[2], er, ea, eb);
  const double spin = angular_velocity(c).dot(er);
  const double ca = std::cos(c[1]);
  out[0] = spin;
  out[1] = c[14] * ca * ca + 2 * params_.r / (7 * params_.rc()) * spin * std::sin(c[1]);
}

bool Ball::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

}  // namespace cstab

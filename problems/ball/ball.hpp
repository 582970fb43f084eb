// Ball rolling without slip inside a spherical bowl: Braun & Goldfarb,
// "Simulation of constrained mechanical systems - Part II", Sec. 3.1
// (transcription corrections and initial data: ../shared/papers/NOTES.md).
//
// Solid ball (m = 1, r = 1, I = 2/5 m r^2) inside a bowl of radius R = 8,
// g = 9.81. The bowl's centre is the origin, z points up; the ball's centre
// is at c = rho e_rho with the spherical basis of the paper's footnote 5
//     e_rho   = ( cos a cos b,  cos a sin b, -sin a)
//     e_alpha = (-sin a cos b, -sin a sin b, -cos a) = d e_rho / d alpha
//     e_beta  = (-sin b,        cos b,        0    ) = d e_rho / d beta / cos a
// (right-handed: e_rho x e_alpha = e_beta), so the centre's height is
// -rho sin(alpha) and alpha = pi/2 is the bottom of the bowl.
//
// Two independent formulations:
//
//  * BallMechanical ("mechanical"): the paper's redundant coordinates
//      q = [rho, alpha, beta, e1 (3), e2 (3), e3 (3)]     (12)
//    with e_i the body-fixed axes as 3-vectors. Kinetic energy
//      T = 1/2 m (rho'^2 + rho^2 alpha'^2 + rho^2 cos^2(alpha) beta'^2)
//        + 1/2 sum_i J_i |e_i'|^2,   J_i = I/2
//    (for orthonormal e_i, sum_i |e_i'|^2 = 2 |omega|^2, so the rotational
//    part is 1/2 I |omega|^2), V = -m g rho sin(alpha), hence
//      M = diag(m, m rho^2, m rho^2 cos^2 alpha, I/2 (x9)) and
//      Q = [ m rho (alpha'^2 + cos^2(alpha) beta'^2) + m g sin(alpha),
//           -m rho (2 rho' alpha' + rho sin(alpha) cos(alpha) beta'^2) + m g rho cos(alpha),
//           -2 m rho (rho' cos^2(alpha) - rho alpha' sin(alpha) cos(alpha)) beta',
//            0 (x9) ]
//    (Lagrange's equations; the transcription's Q lost the gravity sign.)
//    Holonomic (7): rho - (R - r) = 0, e_i . e_j - delta_ij = 0 (i <= j).
//    Non-holonomic (2): e_alpha . v_P = 0, e_beta . v_P = 0 where the
//    velocity of the ball's material point at the contact is
//      v_P = v_C + sum_i r (e_i . e_rho) e_i',
//      v_C = rho' e_rho + rho alpha' e_alpha + rho cos(alpha) beta' e_beta,
//    i.e. rho alpha' + r sum_i (e_i.e_rho)(e_alpha.e_i') = 0 and
//    rho cos(alpha) beta' + r sum_i (e_i.e_rho)(e_beta.e_i') = 0 (the
//    e_rho component repeats rho' = 0 and is left out). With these sign
//    conventions the paper's initial omega(0) satisfies both rows exactly
//    (omega x r e_rho = -v_C): no convention needed changing.
//    Energy law E = 1/2 v^T M v + V.
//
//  * BallNewtonEuler ("newton-euler"): the ball as a rigid body with the
//    contact force eliminated, used as the reference and as the
//    constraint-free baseline (`--method minimal`); see ball.cpp.
//
// Canonical coordinates (the series columns): q then v =
//   rho, alpha, beta, e1x, e1y, e1z, e2x, e2y, e2z, e3x, e3y, e3z,
//   rhodot, alphadot, betadot, e1xdot, e1ydot, e1zdot, e2xdot, ..., e3zdot.
// beta is continuous (not wrapped to (-pi, pi]).
// First integrals besides energy: "spin" = omega . e_rho with
// omega = 1/2 sum_i e_i x e_i', and the paper's "eps" =
// beta' cos^2(alpha) + 2 r / (7 (R - r)) omega_rho sin(alpha).
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/problem.hpp"
#include "methods/affine.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"

namespace cstab {

struct BallParameters {
  double m = 1.0;   // ball mass
  double r = 1.0;   // ball radius
  double R = 8.0;   // bowl radius
  double g = 9.81;
  // Initial data (NOTES.md).
  double alpha0 = std::numbers::pi / 4, beta0 = 0.0;
  double alphadot0 = 0.5, betadot0 = 1.0, omega_rho0 = 1.0;

  double inertia() const { return 0.4 * m * r * r; }  // solid sphere
  double rc() const { return R - r; }                 // radius of the centre's sphere
};

namespace ball_detail {

template <class S>
using V3 = Eigen::Matrix<S, 3, 1>;

template <class S>
S dot3(const V3<S>& a, const V3<S>& b) {
  return a(0) * b(0) + a(1) * b(1) + a(2) * b(2);
}

// e_rho, e_alpha, e_beta (footnote 5).
template <class S>
void basis(const S& alpha, const S& beta, V3<S>& er, V3<S>& ea, V3<S>& eb) {
  using std::cos;
  using std::sin;
  const S ca = cos(alpha), sa = sin(alpha), cb = cos(beta), sb = sin(beta);
  er << ca * cb, ca * sb, -sa;
  ea << -sa * cb, -sa * sb, -ca;
  eb << -sb, cb, S(0.0);
}

}  // namespace ball_detail

class BallMechanical {
 public:
  static constexpr int kCoords = 12, kHolonomic = 7, kNonholonomic = 2;
  static constexpr bool kHasEnergy = true;
  enum { qRHO = 0, qALPHA = 1, qBETA = 2, qE1 = 3, qE2 = 6, qE3 = 9 };

  explicit BallMechanical(const BallParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  static std::vector<ConstraintInfo> constraints();
  void initial_state(Vec<double, 12>& q, Vec<double, 12>& v) const;
  void to_canonical(double, const Vec<double, 12>& q, const Vec<double, 12>& v, double* c) const {
    vmap<12>(c) = q;
    vmap<12>(c + 12) = v;
  }

  template <class S>
  void mass(const S&, const Vec<S, 12>& q, Eigen::Matrix<S, 12, 12>& M) const {
    using std::cos;
    const S rho = q(qRHO), ca = cos(q(qALPHA));
    M.setZero();
    M(0, 0) = S(p_.m);
    M(1, 1) = p_.m * rho * rho;
    M(2, 2) = p_.m * rho * rho * ca * ca;
    const double J = 0.5 * p_.inertia();
    for (int i = 3; i < 12; ++i) M(i, i) = S(J);
  }

  template <class S>
  void forces(const S&, const Vec<S, 12>& q, const Vec<S, 12>& v, Vec<S, 12>& Q) const {
    using std::cos;
    using std::sin;
    const double m = p_.m, g = p_.g;
    const S rho = q(qRHO), ca = cos(q(qALPHA)), sa = sin(q(qALPHA));
    const S rd = v(qRHO), ad = v(qALPHA), bd = v(qBETA);
    Q(0) = m * rho * (ad * ad + ca * ca * bd * bd) + m * g * sa;
    Q(1) = -m * rho * (2.0 * rd * ad + rho * sa * ca * bd * bd) + m * g * rho * ca;
    Q(2) = -2.0 * m * rho * (rd * ca * ca - rho * ad * sa * ca) * bd;
    for (int i = 3; i < 12; ++i) Q(i) = S(0.0);
  }

  template <class S>
  void holonomic(const S&, const Vec<S, 12>& q, Vec<S, 7>& phi) const {
    phi(0) = q(qRHO) - p_.rc();
    int k = 1;
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) {
        phi(k) = q(3 + 3 * i) * q(3 + 3 * j) + q(4 + 3 * i) * q(4 + 3 * j) + q(5 + 3 * i) * q(5 + 3 * j);
        if (i == j) phi(k) -= 1.0;
        ++k;
      }
  }

  // The same rows with their derivatives in closed form (MechanicalTerms):
  // phi_k = e_i . e_j - delta_ij has gradient e_j in e_i and e_i in e_j, and
  // second derivative along v 2 (e_i' . e_j'); rho - rc is linear.
  template <class Terms>
  void closed_form_holonomic(double, const Vec<double, 12>& q, const Vec<double, 12>* v, Terms& terms) const {
    auto J = terms.A.template topRows<7>();
    J.setZero();
    terms.phi_t.setZero();
    terms.phi(0) = q(qRHO) - p_.rc();
    J(0, qRHO) = 1.0;
    if (v) terms.gamma(0) = 0.0;
    int k = 1;
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) {
        const auto ei = q.template segment<3>(3 + 3 * i), ej = q.template segment<3>(3 + 3 * j);
        terms.phi(k) = ei.dot(ej) - (i == j ? 1.0 : 0.0);
        J.template block<1, 3>(k, 3 + 3 * i) += ej.transpose();
        J.template block<1, 3>(k, 3 + 3 * j) += ei.transpose();
        if (v) terms.gamma(k) = 2.0 * v->template segment<3>(3 + 3 * i).dot(v->template segment<3>(3 + 3 * j));
        ++k;
      }
  }

  template <class S>
  void nonholonomic(const S&, const Vec<S, 12>& q, const Vec<S, 12>& v, Vec<S, 2>& psi) const {
    using namespace ball_detail;
    using std::cos;
    V3<S> er, ea, eb;
    basis(q(qALPHA), q(qBETA), er, ea, eb);
    // v_P^C = sum_i r (e_i . e_rho) e_i'
    V3<S> vpc;
    vpc.setZero();
    for (int i = 0; i < 3; ++i) {
      const int k = 3 + 3 * i;
      const S w = p_.r * (q(k) * er(0) + q(k + 1) * er(1) + q(k + 2) * er(2));
      for (int d = 0; d < 3; ++d) vpc(d) += w * v(k + d);
    }
    const S rho = q(qRHO);
    psi(0) = rho * v(qALPHA) + dot3(ea, vpc);
    psi(1) = rho * cos(q(qALPHA)) * v(qBETA) + dot3(eb, vpc);
  }

  // The rolling rows in closed form (MechanicalTerms). With u_i = e_i',
  // w_i = r (e_i . e_rho) and v_P^C = sum_i w_i u_i: G has rho (alpha'),
  // rho cos(alpha) (beta') and w_i e_alpha / w_i e_beta (u_i). Along the
  // motion e_rho' = e_alpha alpha' + cos(alpha) e_beta beta',
  // e_alpha' = -e_rho alpha' - sin(alpha) e_beta beta',
  // e_beta' = -(cos beta, sin beta, 0) beta', and
  // (v_P^C)' = sum_i r (u_i . e_rho + e_i . e_rho') u_i with u frozen.
  template <class Terms>
  void closed_form_nonholonomic(double, const Vec<double, 12>& q, const Vec<double, 12>& v, Terms& terms) const {
    using namespace ball_detail;
    V3<double> er, ea, eb;
    basis(q(qALPHA), q(qBETA), er, ea, eb);
    const double ca = std::cos(q(qALPHA)), sa = std::sin(q(qALPHA));
    const double cb = std::cos(q(qBETA)), sb = std::sin(q(qBETA));
    const double rho = q(qRHO), rd = v(qRHO), ad = v(qALPHA), bd = v(qBETA);
    const V3<double> er_dot = ea * ad + ca * bd * eb;
    const V3<double> ea_dot = -er * ad - sa * bd * eb;
    const V3<double> eb_dot(-cb * bd, -sb * bd, 0.0);
    V3<double> vpc = V3<double>::Zero(), vpc_dot = V3<double>::Zero();
    auto G = terms.A.template bottomRows<2>();
    G.setZero();
    G(0, qALPHA) = rho;
    G(1, qBETA) = rho * ca;
    for (int i = 0; i < 3; ++i) {
      const int k = 3 + 3 * i;
      const auto e = q.template segment<3>(k);
      const auto u = v.template segment<3>(k);
      const double w = p_.r * e.dot(er);
      vpc += w * u;
      vpc_dot += p_.r * (u.dot(er) + e.dot(er_dot)) * u;
      G.template block<1, 3>(0, k) = w * ea.transpose();
      G.template block<1, 3>(1, k) = w * eb.transpose();
    }
    terms.velocity(7) = rho * ad + ea.dot(vpc);
    terms.velocity(8) = rho * ca * bd + eb.dot(vpc);
    terms.gamma(7) = rd * ad + ea_dot.dot(vpc) + ea.dot(vpc_dot);
    terms.gamma(8) = (rd * ca - rho * sa * ad) * bd + eb_dot.dot(vpc) + eb.dot(vpc_dot);
  }

  template <class S>
  S energy(const S&, const Vec<S, 12>& q, const Vec<S, 12>& v) const {
    using std::cos;
    using std::sin;
    const S rho = q(qRHO), ca = cos(q(qALPHA));
    const S rd = v(qRHO), ad = v(qALPHA), bd = v(qBETA);
    S rot = S(0.0);
    for (int i = 3; i < 12; ++i) rot += v(i) * v(i);
    return 0.5 * p_.m * (rd * rd + rho * rho * (ad * ad + ca * ca * bd * bd)) + 0.25 * p_.inertia() * rot -
           p_.m * p_.g * rho * sin(q(qALPHA));
  }

  const BallParameters& parameters() const { return p_; }

 private:
  BallParameters p_;
};

// Newton-Euler model, state y = [u (3), omega (3), quaternion (4), beta (1)]:
// u is the direction of the centre (n = u/|u|, c = (R - r) n), omega the
// angular velocity in the fixed frame, the unit quaternion (w, x, y, z) maps
// body to fixed axes (e_i = columns of its rotation matrix), and beta the
// continuous azimuth (only to unwrap atan2). See ball.cpp for the equations.
class BallNewtonEuler {
 public:
  static constexpr int kStates = 11;
  enum { iU = 0, iW = 3, iQ = 6, iBETA = 10 };

  explicit BallNewtonEuler(const BallParameters& p) : p_(p), mech_(p) {}

  std::string formulation_name() const { return "newton-euler"; }
  std::vector<ConstraintInfo> constraints() const { return BallMechanical::constraints(); }
  void initial_state(Vec<double, kStates>& y) const;
  bool rhs(double t, const Vec<double, kStates>& y, Vec<double, kStates>& dy) const;
  void to_canonical(double t, const Vec<double, kStates>& y, double* c) const;
  // The mechanical model's constraints on the mapped state (round-off).
  void residuals(double t, const Vec<double, kStates>& y, double* out) const;
  // Energy of the rigid body (translational + rotational + potential).
  double energy(const Vec<double, kStates>& y) const;

 private:
  BallParameters p_;
  BallMechanical mech_;
};

class Ball {
 public:
  Ball() : mechanical_(params_), minimal_(params_) {}
  explicit Ball(const BallParameters& p) : params_(p), mechanical_(p), minimal_(p) {}

  ProblemInfo info() const;
  const BallMechanical& mechanical() const { return mechanical_; }
  const BallNewtonEuler& minimal() const { return minimal_; }
  const BallParameters& parameters() const { return params_; }

  // E = 1/2 v^T M v + V on the canonical state.
  double energy(double t, const double* canonical) const;
  // out[0] = spin omega . e_rho, out[1] = eps-integral.
  void first_integrals(double t, const double* canonical, double* out) const;
  // Newton-Euler solution by GSL rk8pd at rtol = atol = 1e-13, cached by time.
  bool reference(double t, double* canonical) const;

  // Helpers on canonical states: the centre rho e_rho and
  // omega = 1/2 sum_i e_i x e_i'.
  static Eigen::Vector3d centre(const double* canonical);
  static Eigen::Vector3d angular_velocity(const double* canonical);

 private:
  BallParameters params_;
  BallMechanical mechanical_;
  BallNewtonEuler minimal_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 24);
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(BallMechanical);

}  // namespace cstab

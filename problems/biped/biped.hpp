// Seven-link planar biped: Braun & Goldfarb, "Simulation of constrained
// mechanical systems - Part II", Sec. 3.2 (their Fig. 3). Notes on the
// transcription: ../shared/papers/NOTES.md.
//
// COORDINATES (9, absolute, SI units, angles in rad counterclockwise from +x):
//     q = [x, y, theta, theta1, theta2, theta3, theta4, theta5, theta6]
// +x is the walking direction, +y up, the ground is y = 0. With
// u(a) = (cos a, sin a) and R(a) the rotation by a:
//   (x, y)    centre of mass of the HAT segment (head, arms, trunk);
//   theta     HAT axis: hip -> (x, y) is  l_c u(theta)  (upright: theta ~ pi/2)
//   hip       (x, y) - l_c u(theta)
//   theta1/4  thigh of leg 1/2: knee  = hip  - l1 u(theta1)   (knee -> hip is u(theta1))
//   theta2/5  shank of leg 1/2: ankle = knee - l2 u(theta2)
//   theta3/6  foot of leg 1/2, rotation of the sole from the horizontal; in the
//             foot frame (origin ankle, x' forward along the sole, y' up) the
//             heel is (-b, -h) and the toe (a, -h):
//               heel = ankle + R(theta3)(-b, -h),   toe = ankle + R(theta6)(a, -h).
// Leg 1 is the forward leg (at q(0) its ankle is ahead of the hip), leg 2 the
// backward one. These definitions reproduce the paper's constraints term by
// term (y-component of heel1 and toe2, time derivative of their x-components):
//   y_heel1 = y - l_c sin(theta) - l1 sin(theta1) - l2 sin(theta2) - h cos(theta3) - b sin(theta3)
//   y_toe2  = y - l_c sin(theta) - l1 sin(theta4) - l2 sin(theta5) - h cos(theta6) + a sin(theta6)
//   d/dt x_heel1 = x' + l_c sin(theta) theta' + l1 sin(theta1) theta1' + l2 sin(theta2) theta2'
//                  + (h cos(theta3) + b sin(theta3)) theta3'
//   d/dt x_toe2  = ... + (h cos(theta6) - a sin(theta6)) theta6'
// so the paper's "forward heel and backward toe on the ground" fixes b as the
// HEEL offset behind the ankle and a as the TOE offset ahead of it (with +x
// forward: the forward foot's contact lies behind its ankle). Two facts fix
// the remaining reading: knee flexion theta2 < theta1 (Phi_3) then puts the
// ankle behind the knee line, a natural knee for walking towards +x; and
// x(0) = 0.056 = l_c cos(theta(0)) within 1.5 mm puts the hip at x = 0 at
// t = 0, which identifies (x, y) as the HAT centre of mass at l_c ~ 0.32 m.
//
// CONSTRAINTS (omega = pi rad/s, kappa(t) = pi/10 (1 - cos(omega t))):
//   Phi_1 = y_heel1 = 0                      forward heel on the ground
//   Phi_2 = y_toe2 = 0                       backward toe on the ground
//   Phi_3 = theta2 - theta1 + kappa(t)       knee 1 flexion
//   Phi_4 = theta5 - theta4 + kappa(t)       knee 2 flexion
//   Phi_5 = theta - (4 pi/9 - pi/18 (1 - cos(omega t)))   trunk
//   Phi_6 = theta3 - pi/18 (1 + cos(omega t))             foot 1
//   Phi_7 = theta6 + pi/18 (1 - cos(omega t))             foot 2
//   Psi_1 = d/dt x_heel1 = 0, Psi_2 = d/dt x_toe2 = 0     (contacts do not slide)
// The Psi rows are integrable: x_heel1 = X1, x_toe2 = X2 with constants the
// paper treats as unknown, so they stay velocity constraints. The 9 rows are
// independent along the motion: the motion is pure kinematics, the mass matrix
// only shapes the reactions and the transient from inconsistent data. The
// constraints do work: there is no energy law (kHasEnergy = false).
//
// PARAMETERS (body mass m = 75 kg, height H = 1.78 m, g = 9.81):
// Winter, "Biomechanics and Motor Control of Human Movement" (4th ed., 2009),
//  * Fig. 4.1 (segment lengths as fractions of H, after Drillis & Contini):
//    greater trochanter (hip) 0.530 H, knee 0.285 H, ankle 0.039 H,
//    glenohumeral joint (shoulder) 0.818 H, foot length 0.152 H. Hence
//      thigh  l1 = 0.245 H = 0.43610 m      shank l2 = 0.246 H = 0.43788 m
//      ankle height h = 0.039 H = 0.06942 m  HAT (hip-shoulder) 0.288 H = 0.51264 m
//  * Table 4.1 (Dempster's data): mass fraction, centre of mass from the
//    proximal end (fraction of segment length), radius of gyration about the
//    centre of mass (fraction of segment length):
//      HAT   (greater trochanter - glenohumeral) 0.678, 0.626, 0.496
//      thigh (greater trochanter - knee)         0.100, 0.433, 0.323
//      leg   (knee - medial malleolus)           0.0465, 0.433, 0.302
//      foot  (lateral malleolus - metatarsal II) 0.0145, 0.50,  0.475
//    (the seven masses sum to 1). So l_c = 0.626 * 0.288 H = 0.32091 m is the
//    hip -> HAT centre of mass distance, and with m = 75 kg:
//      HAT   50.85 kg, I = 50.85 (0.496 * 0.51264)^2  = 3.2876 kg m^2
//      thigh  7.5 kg,  com 0.433 l1 below the hip,   I = 7.5 (0.323 l1)^2 = 0.14881
//      shank  3.4875 kg, com 0.433 l2 below the knee, I = 3.4875 (0.302 l2)^2 = 0.060995
//      foot   1.0875 kg, com halfway ankle -> metatarsal head (taken at the toe
//             point (a, -h)): (a/2, -h/2) in the foot frame,
//             I = 1.0875 (0.475 sqrt(a^2 + h^2))^2 = 0.011109
//  * The heel offset b is not in Winter's tables: b = 0.039 H = 0.06942 m
//    (26 % of the foot length, a typical malleolus-to-heel distance), and the
//    toe point closes the foot length: a = 0.152 H - b = 0.113 H = 0.20114 m.
// With these values the paper's q(0) = [0.056, 1.2, 1.4, 2, 2, 0.35, 1.19,
// 1.19, 0], v(0) = 0 is slightly inconsistent: Phi_1 = 3.4e-5 m,
// Phi_2 = 3.0e-3 m, Phi_5 = 3.7e-3 rad, Phi_6 = 9.3e-4 rad, the rest (and every
// velocity-level residual: v = 0 and Phi_t(0) = 0) vanish. (The paper's
// angles are rounded: theta(0) = 1.4 for 4 pi/9, theta3(0) = 0.35 for pi/9.)
// At H = 1.785 m Phi_2 would drop below 0.5 mm; the rounder H = 1.78 m is kept.
// (Segment-length fractions are from Winter's Fig. 4.1 as commonly quoted;
// Table 4.1 was checked against a transcription, the figure was not.)
//
// REFERENCE (exact kinematic solution): given the contact abscissae X1, X2,
// the 9 equations [Phi(t, q); x_heel1(q) - X1; x_toe2(q) - X2] = 0 fix q(t):
// closed form (the hip is the upper intersection of two circles of radius
// |l1 + l2 e^{-i kappa}| about the two ankles), polished by Newton on all 9
// equations; velocities from [J; G] v = [-Phi_t; 0]. The motion is periodic
// (2 s). Which X1, X2? q(0) is inconsistent, so the constants are a
// choice. reference() uses the contact abscissae of q(0) itself,
// X = (x_heel1(q0), x_toe2(q0)): the data's own values, which the velocity
// constraints keep (Psi(q0, v0 = 0) = 0). Methods that correct through forces
// (baumgarte, pesterev, and none, which does not correct at all) keep Psi = 0
// along the run and so keep exactly these contacts. Methods that move the
// positions directly (braun-goldfarb's q' correction, projection) shift the
// contacts while they correct: by (-4.6e-4, +4.9e-3) m here. Where
// braun-goldfarb lands is predicted by the end point of the correction flow
//     dq/dtau = -M(q)^-1 J^T (J M(q)^-1 J^T)^-1 Phi(0, q)    (Phi = Phi_0 e^-tau)
// from q(0) (flow_initial_configuration()): its transient
// q' = v - M^-1 J^T (J M^-1 J^T)^-1 (Phi' + Phi / dt) goes there in the limit
// step/dt -> 0, then dt -> 0 (measured: 6e-9 m off at step 1e-4, dt = 1e-3;
// 6e-7 m at step = dt = 1e-3, where rk4 with one step per correction time
// constant discretizes the transient itself; 8e-6 m at step 1e-3, dt = 0.03,
// where the motion proceeds during the longer transient). The kinetic-metric
// projection argmin (q - q0)^T M(q0) (q - q0) s.t. Phi(0, q) = 0
// (projected_initial_configuration(), what projection approximates) lands
// 8.7e-6 m from the flow's end point. So the harness's reference error at
// t = 10 is ~5e-3 for braun-goldfarb and projection at every step: the
// contact shift, not the integration error. The accuracy check in
// tests/unit/test_biped.cpp reads X1, X2 off the numerical solution after the
// transient and compares the whole motion with the exact solution for those
// constants (exact_state()).
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/problem.hpp"
#include "methods/affine.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"

namespace cstab {

// Every derived value is initialised from body_mass and height in declaration
// order; to change the person, construct with those two changed, e.g.
// BipedParameters{80.0, 1.75} (the rest then follows).
struct BipedParameters {
  // Anthropometry (see the header comment for every source).
  double body_mass = 75.0;  // kg
  double height = 1.78;     // m
  double g = 9.81;
  double omega = std::numbers::pi;  // rad/s

  // Lengths (m).
  double l1 = 0.245 * height;                   // thigh, hip - knee
  double l2 = 0.246 * height;                   // shank, knee - ankle
  double hat_length = (0.818 - 0.530) * height;  // hip - shoulder
  double lc = 0.626 * hat_length;               // hip - HAT centre of mass
  double h = 0.039 * height;                    // ankle height
  double b = 0.039 * height;                    // heel behind the ankle
  double a = 0.152 * height - b;                // toe ahead of the ankle

  // Masses (kg) and moments of inertia about the centres of mass (kg m^2).
  double m_hat = 0.678 * body_mass;
  double m_thigh = 0.100 * body_mass;
  double m_shank = 0.0465 * body_mass;
  double m_foot = 0.0145 * body_mass;
  double thigh_com = 0.433;  // fraction of l1 below the hip
  double shank_com = 0.433;  // fraction of l2 below the knee
  double i_hat = m_hat * std::pow(0.496 * hat_length, 2);
  double i_thigh = m_thigh * std::pow(0.323 * l1, 2);
  double i_shank = m_shank * std::pow(0.302 * l2, 2);
  double i_foot = m_foot * std::pow(0.475 * std::hypot(a, h), 2);

  // The paper's (inconsistent) initial data.
  std::array<double, 9> q0 = {0.056, 1.2, 1.4, 2.0, 2.0, 0.35, 1.19, 1.19, 0.0};
};

// The biped as a mechanical system M(q) q'' = Q(q, q') + A^T lambda.
class BipedMechanical {
 public:
  static constexpr int kCoords = 9, kHolonomic = 7, kNonholonomic = 2;
  static constexpr bool kHasEnergy = false;
  enum { qX, qY, qTH, qT1, qT2, qT3, qT4, qT5, qT6 };

  explicit BipedMechanical(const BipedParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const;
  void initial_state(Vec<double, 9>& q, Vec<double, 9>& v) const;
  void to_canonical(double, const Vec<double, 9>& q, const Vec<double, 9>& v, double* c) const {
    vmap<9>(c) = q;
    vmap<9>(c + 9) = v;
  }
  const BipedParameters& parameters() const { return p_; }

  // ---- kinematics: a material point is (x, y) + sum_k R(q(angle_k)) w_k ----
  struct Link {
    int angle;     // index into q of the angle that rotates w
    double wx, wy;  // body-fixed vector
  };
  struct Chain {
    std::array<Link, 4> links;
    int n;
  };
  // Bodies 0..6: HAT, thigh1, shank1, foot1, thigh2, shank2, foot2 (centres of mass).
  static constexpr int kBodies = 7;
  Chain body_com(int k) const;
  double body_mass(int k) const;
  double body_inertia(int k) const;
  static int body_angle(int k) { return std::array<int, 7>{qTH, qT1, qT2, qT3, qT4, qT5, qT6}[k]; }
  // Points for plotting and constraints.
  Chain hip() const { return {{Link{qTH, -p_.lc, 0}}, 1}; }
  Chain knee(int leg) const;
  Chain ankle(int leg) const;
  Chain heel(int leg) const;  // foot point (-b, -h)
  Chain toe(int leg) const;   // foot point (a, -h)

  template <class S>
  Vec<S, 2> point(const Vec<S, 9>& q, const Chain& c) const {
    using std::cos;
    using std::sin;
    Vec<S, 2> r(q(qX), q(qY));
    for (int k = 0; k < c.n; ++k) {
      const S ca = cos(q(c.links[k].angle)), sa = sin(q(c.links[k].angle));
      r(0) += ca * c.links[k].wx - sa * c.links[k].wy;
      r(1) += sa * c.links[k].wx + ca * c.links[k].wy;
    }
    return r;
  }

  // M = sum_k m_k J_k^T J_k + sum_k I_k e_k e_k^T, J_k = d(com_k)/dq.
  template <class S>
  void mass(const S&, const Vec<S, 9>& q, Eigen::Matrix<S, 9, 9>& M) const {
    M.setZero();
    for (int k = 0; k < kBodies; ++k) {
      Eigen::Matrix<S, 2, 9> J;
      com_jacobian(q, body_com(k), J);
      M += body_mass(k) * (J.transpose() * J);
      M(body_angle(k), body_angle(k)) += body_inertia(k);
    }
  }

  // Q = sum_k m_k J_k^T (g_vec - Jdot_k v), with the velocity-product part of
  // the acceleration Jdot_k v = -sum_links R(q_a) w q_a'^2 (planar rotations).
  template <class S>
  void forces(const S&, const Vec<S, 9>& q, const Vec<S, 9>& v, Vec<S, 9>& Q) const {
    using std::cos;
    using std::sin;
    Q.setZero();
    for (int k = 0; k < kBodies; ++k) {
      const Chain c = body_com(k);
      Eigen::Matrix<S, 2, 9> J;
      com_jacobian(q, c, J);
      Vec<S, 2> f(S(0.0), S(-p_.g));
      for (int i = 0; i < c.n; ++i) {
        const int a = c.links[i].angle;
        const S ca = cos(q(a)), sa = sin(q(a));
        const S w2 = v(a) * v(a);
        f(0) += (ca * c.links[i].wx - sa * c.links[i].wy) * w2;
        f(1) += (sa * c.links[i].wx + ca * c.links[i].wy) * w2;
      }
      Q += body_mass(k) * (J.transpose() * f);
    }
  }

  // The paper's Phi_q, written as printed (checked against point() in the tests).
  template <class S>
  void holonomic(const S& t, const Vec<S, 9>& q, Vec<S, 7>& phi) const {
    using std::cos;
    using std::sin;
    const double pi = std::numbers::pi;
    const S c = cos(p_.omega * t);
    const S kappa = pi / 10 * (1.0 - c);
    const S trunk = sin(q(qTH)) * p_.lc;
    phi(0) = q(qY) - trunk - p_.l1 * sin(q(qT1)) - p_.l2 * sin(q(qT2)) - p_.h * cos(q(qT3)) -
             p_.b * sin(q(qT3));
    phi(1) = q(qY) - trunk - p_.l1 * sin(q(qT4)) - p_.l2 * sin(q(qT5)) - p_.h * cos(q(qT6)) +
             p_.a * sin(q(qT6));
    phi(2) = q(qT2) - q(qT1) + kappa;
    phi(3) = q(qT5) - q(qT4) + kappa;
    phi(4) = q(qTH) - (4 * pi / 9 - pi / 18 * (1.0 - c));
    phi(5) = q(qT3) - pi / 18 * (1.0 + c);
    phi(6) = q(qT6) + pi / 18 * (1.0 - c);
  }

  // The paper's Phi_v = G(q) v (no inhomogeneous term).
  template <class S>
  void nonholonomic(const S&, const Vec<S, 9>& q, const Vec<S, 9>& v, Vec<S, 2>& psi) const {
    using std::cos;
    using std::sin;
    const S trunk = p_.lc * sin(q(qTH)) * v(qTH);
    psi(0) = v(qX) + trunk + p_.l1 * sin(q(qT1)) * v(qT1) + p_.l2 * sin(q(qT2)) * v(qT2) +
             (p_.h * cos(q(qT3)) + p_.b * sin(q(qT3))) * v(qT3);
    psi(1) = v(qX) + trunk + p_.l1 * sin(q(qT4)) * v(qT4) + p_.l2 * sin(q(qT5)) * v(qT5) +
             (p_.h * cos(q(qT6)) - p_.a * sin(q(qT6))) * v(qT6);
  }

  // Contact abscissae x_heel1(q), x_toe2(q): the integrals of Psi.
  template <class S>
  Vec<S, 2> contact_abscissae(const Vec<S, 9>& q) const {
    return Vec<S, 2>(point(q, heel(0))(0), point(q, toe(1))(0));
  }

 private:
  template <class S>
  void com_jacobian(const Vec<S, 9>& q, const Chain& c, Eigen::Matrix<S, 2, 9>& J) const {
    using std::cos;
    using std::sin;
    J.setZero();
    J(0, qX) = S(1.0);
    J(1, qY) = S(1.0);
    for (int i = 0; i < c.n; ++i) {
      const int a = c.links[i].angle;
      const S ca = cos(q(a)), sa = sin(q(a));
      // d/dq_a R(q_a) w = R(q_a) (-w_y, w_x)
      J(0, a) += -sa * c.links[i].wx - ca * c.links[i].wy;
      J(1, a) += ca * c.links[i].wx - sa * c.links[i].wy;
    }
  }

  BipedParameters p_;
};

class Biped {
 public:
  Biped();
  explicit Biped(const BipedParameters& p);

  ProblemInfo info() const;
  const BipedMechanical& mechanical() const { return mechanical_; }
  const BipedParameters& parameters() const { return params_; }

  // Exact motion with contact abscissae X = (x_heel1, x_toe2): canonical
  // state [q; v] at t. false if the configuration does not exist (legs too
  // short) or Newton does not converge.
  bool exact_state(double t, const Vec<double, 2>& X, double* canonical) const;
  // Configuration only: closed form, then Newton on the 9 equations.
  bool exact_configuration(double t, const Vec<double, 2>& X, Vec<double, 9>& q) const;
  // Closed form alone (used as Newton's start and as an independent check).
  bool closed_form_configuration(double t, const Vec<double, 2>& X, Vec<double, 9>& q) const;
  // Newton on [Phi(t, q); x_c(q) - X] = 0 from q; returns the final max-norm
  // residual in *residual. false if it does not converge.
  bool newton(double t, const Vec<double, 2>& X, Vec<double, 9>& q, double* residual = nullptr) const;

  // Two consistent configurations derived from the paper's q(0) (Phi(0, q) = 0):
  // the kinetic-metric projection argmin (q - q0)^T M(q0) (q - q0), and the end
  // point of the correction flow dq/dtau = -M^-1 J^T (J M^-1 J^T)^-1 Phi(0, q),
  // which is where braun-goldfarb's transient goes as dt -> 0.
  const Vec<double, 9>& projected_initial_configuration() const { return q_proj_; }
  const Vec<double, 9>& flow_initial_configuration() const { return q_flow_; }
  // The contact abscissae reference() uses: those of q(0).
  const Vec<double, 2>& reference_constants() const { return x_ref_; }
  // Those of the correction flow's end point (braun-goldfarb's landing).
  Vec<double, 2> flow_constants() const { return mechanical_.contact_abscissae(q_flow_); }

  bool reference(double t, double* canonical) const { return exact_state(t, x_ref_, canonical); }

 private:
  BipedParameters params_;
  BipedMechanical mechanical_;
  Vec<double, 9> q_proj_, q_flow_;
  Vec<double, 2> x_ref_;
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(BipedMechanical);

}  // namespace cstab

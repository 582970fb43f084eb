// Heavy wheel (thin hoop) with a pendulum rolling without slip on a curve:
// Pesterev, Matrosov, Morozov, "Control-based approach to numerical
// integration of rolling equations". Two independent formulations:
//
//  * WheelStateSpace - the paper's affine form: X = [x, xdot, z, zdot, theta,
//    thetadot, phi, phidot, alpha], reactions N = [R_x, R_z, U] with
//    alpha' = U (eq. 21), dynamics (16), outputs (18)-(20), relative degree
//    {2, 1, 1}. Its state is the problem's canonical coordinate set.
//  * WheelMinimal - Lagrange's equations in the two degrees of freedom
//    (s = contact point abscissa, phi), the curve geometry in closed form and
//    theta integrated from rolling; derived separately (see wheel.cpp) and
//    used as the reference solution and as the constraint-free baseline.
//
// Corrections to the transcription (../shared/papers/NOTES.md): the curve is
//     z = p(x) = x^4 + 0.13 x^3 - 0.5 x^2 - 0.13 x + 0.5,  h(x, z) = z - p(x),
// and g = 9.81 (the paper gives none).
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/problem.hpp"
#include "methods/affine.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"
#include "problems/wheel/wheel_parameters.hpp"

namespace cstab {

class WheelStateSpace {
 public:
  static constexpr int kStates = 9;
  static constexpr int kInputs = 3;
  static constexpr std::array<int, kInputs> kRelativeDegree = {2, 1, 1};
  enum { iX, iXD, iZ, iZD, iTH, iTHD, iPHI, iPHID, iALPHA };

  explicit WheelStateSpace(const WheelParameters& p) : p_(p) {}

  std::string formulation_name() const { return "state-space"; }
  static std::vector<ConstraintInfo> constraints();
  void initial_state(Vec<double, kStates>& X0) const;
  void to_canonical(double, const Vec<double, kStates>& X, double* c) const {
    vmap<kStates>(c) = X;
  }

  // Eq. (16) with N = 0, and alpha' = 0 (eq. 21 without U).
  template <class S>
  void drift(const S&, const Vec<S, kStates>& X, Vec<S, kStates>& F) const {
    using std::cos;
    using std::sin;
    const double Mm = p_.M + p_.m;
    const S w2 = X(iPHID) * X(iPHID);
    F(iX) = X(iXD);
    F(iXD) = p_.m * p_.l * w2 * sin(X(iPHI)) / Mm;
    F(iZ) = X(iZD);
    F(iZD) = -p_.m * p_.l * w2 * cos(X(iPHI)) / Mm - p_.g;
    F(iTH) = X(iTHD);
    F(iTHD) = S(0.0);
    F(iPHI) = X(iPHID);
    F(iPHID) = S(0.0);
    F(iALPHA) = S(0.0);
  }

  // Columns multiply R_x, R_z, U (eqs. 16, 17, 21).
  void input_matrix(double, const Vec<double, kStates>& X, Eigen::Matrix<double, kStates, kInputs>& B) const {
    const double gamma = p_.m / p_.M, Mm = p_.M + p_.m;
    const double s = std::sin(X(iPHI)), c = std::cos(X(iPHI));
    const double a = 1 + gamma * c * c, b = gamma * s * c, cc = 1 + gamma * s * s;
    B.setZero();
    B(iXD, 0) = a / Mm;
    B(iXD, 1) = b / Mm;
    B(iZD, 0) = b / Mm;
    B(iZD, 1) = cc / Mm;
    B(iTHD, 0) = -std::sin(X(iALPHA)) / (p_.M * p_.r);
    B(iTHD, 1) = std::cos(X(iALPHA)) / (p_.M * p_.r);
    B(iPHID, 0) = -c / (p_.M * p_.l);
    B(iPHID, 1) = -s / (p_.M * p_.l);
    B(iALPHA, 2) = 1.0;
  }

  // f1 = h(x_a, z_a) (18), f2 = rolling (19), f3 = tangency (20).
  template <class S>
  void outputs(const S&, const Vec<S, kStates>& X, Vec<S, kInputs>& f) const {
    using std::cos;
    using std::sin;
    const S ca = cos(X(iALPHA)), sa = sin(X(iALPHA));
    const S xa = X(iX) + p_.r * ca;
    const S za = X(iZ) + p_.r * sa;
    f(0) = za - p_.p(xa);
    f(1) = -X(iXD) * sa + X(iZD) * ca + p_.r * X(iTHD);
    f(2) = -p_.dp(xa) * sa - ca;  // h_x sin(alpha) - h_z cos(alpha), h_x = -p', h_z = 1
  }

  // The Lie-derivative jet (LieJet) in closed form: about a third of the
  // cost of nested AD, which dominated the state-space right-hand side
  // (docs/measurements.md, Speed). With xa = x + r cos(alpha), P_k = p^(k)(xa):
  //   L_F f1 = zdot - P1 xdot,  L_F^2 f1 = F_zd - P1 F_xd - P2 xdot^2,
  //   L_B L_F f1 = -P1 B_xd + B_zd + P2 r sin(alpha) xdot B_alpha,
  //   L_F f2 = -sin(alpha) F_xd + cos(alpha) F_zd,
  //   L_B f2 = -sin(alpha) B_xd + cos(alpha) B_zd + r B_thd - (xdot cos(alpha) + zdot sin(alpha)) B_alpha,
  //   L_F f3 = -P2 sin(alpha) xdot,
  //   L_B f3 = (P2 r sin^2(alpha) - P1 cos(alpha) + sin(alpha)) B_alpha.
  // tests/unit/test_wheel.cpp checks it against the AD jet and finite differences.
  template <class Jet>
  void closed_form_jet(double t, const Vec<double, kStates>& X, Jet& jet) const {
    const double Mm = p_.M + p_.m, gamma = p_.m / p_.M;
    const double sp = std::sin(X(iPHI)), cp = std::cos(X(iPHI));
    const double sa = std::sin(X(iALPHA)), ca = std::cos(X(iALPHA));
    const double xd = X(iXD), zd = X(iZD);
    const double w2 = X(iPHID) * X(iPHID);
    auto& F = jet.F;
    F(iX) = xd;
    F(iXD) = p_.m * p_.l * w2 * sp / Mm;  // as drift() rounds it
    F(iZ) = zd;
    F(iZD) = -p_.m * p_.l * w2 * cp / Mm - p_.g;
    F(iTH) = X(iTHD);
    F(iTHD) = 0.0;
    F(iPHI) = X(iPHID);
    F(iPHID) = 0.0;
    F(iALPHA) = 0.0;
    // B as input_matrix builds it, without recomputing the trigonometry.
    const double a = 1 + gamma * cp * cp, b = gamma * sp * cp, cc = 1 + gamma * sp * sp;
    auto& B = jet.B;
    B.setZero();
    B(iXD, 0) = a / Mm;
    B(iXD, 1) = b / Mm;
    B(iZD, 0) = b / Mm;
    B(iZD, 1) = cc / Mm;
    B(iTHD, 0) = -sa / (p_.M * p_.r);
    B(iTHD, 1) = ca / (p_.M * p_.r);
    B(iPHID, 0) = -cp / (p_.M * p_.l);
    B(iPHID, 1) = -sp / (p_.M * p_.l);
    B(iALPHA, 2) = 1.0;

    const double xa = X(iX) + p_.r * ca, za = X(iZ) + p_.r * sa;
    const double P0 = p_.p(xa), P1 = p_.dp(xa), P2 = p_.ddp(xa);
    jet.lower.setZero();
    jet.lower(0, 0) = za - P0;
    jet.lower(0, 1) = zd - P1 * xd;
    jet.lower(1, 0) = -xd * sa + zd * ca + p_.r * X(iTHD);
    jet.lower(2, 0) = -P1 * sa - ca;
    jet.top(0) = F(iZD) - P1 * F(iXD) - P2 * xd * xd;
    jet.top(1) = -sa * F(iXD) + ca * F(iZD);
    jet.top(2) = -P2 * sa * xd;
    for (int j = 0; j < 2; ++j) {
      jet.A(0, j) = -P1 * B(iXD, j) + B(iZD, j);
      jet.A(1, j) = -sa * B(iXD, j) + ca * B(iZD, j) + p_.r * B(iTHD, j);
      jet.A(2, j) = 0.0;
    }
    jet.A(0, 2) = P2 * p_.r * sa * xd;
    jet.A(1, 2) = -(xd * ca + zd * sa);
    jet.A(2, 2) = P2 * p_.r * sa * sa - P1 * ca + sa;
    (void)t;
  }

  const WheelParameters& parameters() const { return p_; }

 private:
  WheelParameters p_;
};

class WheelMinimal {
 public:
  static constexpr int kStates = 5;
  enum { iS, iSD, iPHI, iPHID, iTH };

  explicit WheelMinimal(const WheelParameters& p) : p_(p), ss_(p) {}

  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return WheelStateSpace::constraints(); }
  void initial_state(Vec<double, kStates>& y0) const;
  bool rhs(double t, const Vec<double, kStates>& y, Vec<double, kStates>& dy) const;
  void to_canonical(double t, const Vec<double, kStates>& y, double* c) const;
  void residuals(double t, const Vec<double, kStates>& y, double* out) const;

  // Energy written in the minimal coordinates (independent of the canonical one).
  double energy(const Vec<double, kStates>& y) const;

 private:
  WheelParameters p_;
  WheelStateSpace ss_;
};

// The wheel as a mechanical system: q = (x, z, theta, phi), the mass matrix
// and forces of the Lagrangian (13)-(14); one holonomic constraint
// "signed distance from the centre to the curve = r" (the contact point
// s(q) found by a closest-point Newton solve) and rolling without slip.
class WheelMechanical {
 public:
  static constexpr int kCoords = 4, kHolonomic = 1, kNonholonomic = 1;
  static constexpr bool kHasEnergy = true;
  enum { qX, qZ, qTH, qPHI };

  explicit WheelMechanical(const WheelParameters& p) : p_(p), ss_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const {
    return {{"distance", "holonomic", "signed distance from the centre to the curve minus r"},
            {"rolling", "non-holonomic", "(xdot + p'(s) zdot)/w + r thetadot: no slip at the contact s(q)"}};
  }
  void initial_state(Vec<double, 4>& q, Vec<double, 4>& v) const;
  void to_canonical(double t, const Vec<double, 4>& q, const Vec<double, 4>& v, double* c) const;

  template <class S>
  void mass(const S&, const Vec<S, 4>& q, Eigen::Matrix<S, 4, 4>& M) const {
    using std::cos;
    using std::sin;
    const double Mm = p_.M + p_.m, ml = p_.m * p_.l;
    M.setZero();
    M(qX, qX) = S(Mm);
    M(qZ, qZ) = S(Mm);
    M(qTH, qTH) = S(p_.M * p_.r * p_.r);
    M(qPHI, qPHI) = S(ml * p_.l);
    M(qX, qPHI) = M(qPHI, qX) = ml * cos(q(qPHI));
    M(qZ, qPHI) = M(qPHI, qZ) = ml * sin(q(qPHI));
  }
  template <class S>
  void forces(const S&, const Vec<S, 4>& q, const Vec<S, 4>& v, Vec<S, 4>& Q) const {
    using std::cos;
    using std::sin;
    const double ml = p_.m * p_.l;
    const S w2 = v(qPHI) * v(qPHI);
    Q(qX) = ml * w2 * sin(q(qPHI));
    Q(qZ) = -ml * w2 * cos(q(qPHI)) - (p_.M + p_.m) * p_.g;
    Q(qTH) = S(0.0);
    Q(qPHI) = -p_.m * p_.g * p_.l * sin(q(qPHI));
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 4>& q, Vec<S, 1>& phi) const {
    using std::sqrt;
    const S s = contact(q(qX), q(qZ));
    const S d1 = p_.dp(s);
    phi(0) = ((q(qX) - s) * (-d1) + (q(qZ) - p_.p(s))) / sqrt(1.0 + d1 * d1) - p_.r;
  }
  // The distance row with its derivatives in closed form (MechanicalTerms),
  // from one contact solve in double instead of two on AD types. With
  // n = (-p', 1)/w the unit normal at the contact s (w = sqrt(1 + p'^2)):
  // J = [n, 0, 0] (the distance is stationary in s at the foot), and with
  // ds/d(x, z) = (1, p')/g_s, g_s = 1 + p'^2 + (p - z) p'', and
  // dn/ds = p''/w^3 (-1, -p'), the curvature term is
  //   gamma = v^T (dn/ds ds/d(x, z)) v = -p'' (xdot + p' zdot)^2 / (w^3 g_s).
  template <class Terms>
  void closed_form_holonomic(double, const Vec<double, 4>& q, const Vec<double, 4>* v, Terms& terms) const {
    const double s = contact(q(qX), q(qZ));
    const double p0 = p_.p(s), d1 = p_.dp(s), d2 = p_.ddp(s);
    const double w = std::sqrt(1 + d1 * d1);
    terms.phi(0) = ((q(qX) - s) * (-d1) + (q(qZ) - p0)) / w - p_.r;
    terms.A.template topRows<1>() << -d1 / w, 1 / w, 0, 0;
    terms.phi_t(0) = 0;
    if (v) {
      const double gs = 1 + d1 * d1 + (p0 - q(qZ)) * d2;
      const double along = (*v)(qX) + d1 * (*v)(qZ);
      terms.gamma(0) = -d2 * along * along / (w * w * w * gs);
    }
  }

  // The rolling row in closed form: G = [1/w, p'/w, r, 0], and along the
  // motion d/ds[(xdot + p' zdot)/w] = p'' (zdot - p' xdot)/w^3 with
  // ds/dt = (xdot + p' zdot)/g_s, so
  //   dPsi/dq v = p'' (zdot - p' xdot)(xdot + p' zdot) / (w^3 g_s).
  template <class Terms>
  void closed_form_nonholonomic(double, const Vec<double, 4>& q, const Vec<double, 4>& v, Terms& terms) const {
    const double s = contact(q(qX), q(qZ));
    const double p0 = p_.p(s), d1 = p_.dp(s), d2 = p_.ddp(s);
    const double w = std::sqrt(1 + d1 * d1);
    const double along = v(qX) + d1 * v(qZ);
    terms.velocity(1) = along / w + p_.r * v(qTH);
    terms.A.template bottomRows<1>() << 1 / w, d1 / w, p_.r, 0;
    const double gs = 1 + d1 * d1 + (p0 - q(qZ)) * d2;
    terms.gamma(1) = d2 * (v(qZ) - d1 * v(qX)) * along / (w * w * w * gs);
  }

  template <class S>
  void nonholonomic(const S&, const Vec<S, 4>& q, const Vec<S, 4>& v, Vec<S, 1>& psi) const {
    using std::sqrt;
    const S d1 = p_.dp(contact(q(qX), q(qZ)));
    psi(0) = (v(qX) + d1 * v(qZ)) / sqrt(1.0 + d1 * d1) + p_.r * v(qTH);
  }
  template <class S>
  S energy(const S&, const Vec<S, 4>& q, const Vec<S, 4>& v) const {
    Eigen::Matrix<S, 4, 4> M;
    mass(S(0.0), q, M);
    using std::cos;
    return 0.5 * v.dot(M * v) + (p_.M + p_.m) * p_.g * q(qZ) - p_.m * p_.g * p_.l * cos(q(qPHI));
  }

  // Foot of the normal from (x, z) to the curve: (s - x) + (p(s) - z) p'(s) = 0.
  // Newton in double to convergence, then two Newton steps in S so that AD
  // derivatives (up to second order) of s(x, z) are exact.
  template <class S>
  S contact(const S& x, const S& z) const {
    const double xv = ad::scalar_value(x), zv = ad::scalar_value(z);
    // Start from the foot of the normal at x: the contact is about r (p', -1)/w
    // away from the centre. (Starting at s = x fails on steep, curved parts
    // where the Newton derivative changes sign between x and the contact.)
    const double slope = p_.dp(xv);
    double s = xv + p_.r * slope / std::sqrt(1 + slope * slope);
    for (int it = 0; it < 50; ++it) {
      const double g = (s - xv) + (p_.p(s) - zv) * p_.dp(s);
      double dg = 1 + p_.dp(s) * p_.dp(s) + (p_.p(s) - zv) * p_.ddp(s);
      // Far from the foot the distance may be locally concave: fall back to
      // a gradient step scaled by the Gauss-Newton term. At the foot
      // dg = w^2 (1 - r kappa) > 0, which is small where the curvature
      // nears 1/r (wheel-sharp): there the full Newton step is the right
      // one (a fallback threshold of 0.1 made the iteration crawl and stop
      // 50 iterations short of the foot).
      const double gauss_newton = 1 + p_.dp(s) * p_.dp(s);
      if (dg < 1e-3 * gauss_newton) dg = gauss_newton;
      const double ds = g / dg;
      s -= ds;
      if (std::abs(ds) < 1e-15) break;
    }
    if constexpr (std::is_same_v<S, double>) {
      return s;  // converged: the steps below only carry AD derivatives
    }
    S sa(s);
    for (int k = 0; k < 2; ++k) {
      const S g = (sa - x) + (p_.p(sa) - z) * p_.dp(sa);
      const S dg = 1.0 + p_.dp(sa) * p_.dp(sa) + (p_.p(sa) - z) * p_.ddp(sa);
      sa = sa - g / dg;
    }
    return sa;
  }

 private:
  WheelParameters p_;
  WheelStateSpace ss_;
};

class Wheel {
 public:
  Wheel() : ss_(params_), minimal_(params_), mechanical_(params_) {}
  explicit Wheel(const WheelParameters& p) : params_(p), ss_(p), minimal_(p), mechanical_(p) {}
  // A variant of the wheel (other parameters) registered as a problem of its
  // own; it shares the wheel's instantiations (problems/wheel/wheel_sharp.hpp).
  Wheel(const WheelParameters& p, std::string name, std::string description, double resolution_step)
      : Wheel(p) {
    name_ = std::move(name);
    description_ = std::move(description);
    resolution_step_ = resolution_step;
  }

  ProblemInfo info() const;
  const WheelStateSpace& state_space() const { return ss_; }
  const WheelMinimal& minimal() const { return minimal_; }
  const WheelMechanical& mechanical() const { return mechanical_; }
  double energy(double t, const double* canonical) const;
  // Minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;

 private:
  WheelParameters params_;
  std::string name_, description_;  // empty: the paper's wheel
  double resolution_step_ = 0;
  WheelStateSpace ss_;
  WheelMinimal minimal_;
  WheelMechanical mechanical_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 9);
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(WheelMechanical);

}  // namespace cstab

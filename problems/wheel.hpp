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
#include <vector>

#include "harness/formulation.hpp"
#include "harness/problem.hpp"
#include "methods/affine.hpp"

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

class Wheel {
 public:
  Wheel() : ss_(params_), minimal_(params_) {}
  explicit Wheel(const WheelParameters& p) : params_(p), ss_(p), minimal_(p) {}

  ProblemInfo info() const;
  const WheelStateSpace& state_space() const { return ss_; }
  const WheelMinimal& minimal() const { return minimal_; }
  double energy(double t, const double* canonical) const;
  // Minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;

 private:
  WheelParameters params_;
  WheelStateSpace ss_;
  WheelMinimal minimal_;
  struct Cache {
    std::mutex mutex;
    std::map<double, std::vector<double>> states;
  };
  std::shared_ptr<Cache> cache_ = std::make_shared<Cache>();
};

}  // namespace cstab

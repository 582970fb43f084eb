// Car axis problem as the IVP Test Set for IVP solvers (Bari; Mazzia &
// Magherini, problem "caraxis") defines it: index 3, t in [0, 3].
// A simplified car axis: the left wheel point (xl, yl) and the right wheel
// point (xr, yr), each of mass k = M eps^2 / 2, joined by an axle of length
// L; springs of free length L0 from the origin to the left wheel and from
// the bump (xb, yb) to the right wheel; gravity g; the road excitation
// yb = r sin(w t), xb = sqrt(L^2 - yb^2).
//
//   k (xl, yl, xr, yr)'' = Q(t, q) + G^T lambda,
//   Phi1 = xb(t) xl + yb(t) yl = 0,   Phi2 = (xl - xr)^2 + (yl - yr)^2 - L^2 = 0
// with eps = 1e-2, M = 10, L = 1, L0 = 0.5, r = 0.1, w = 10, g = 1.
// Initial values (consistent): q = (0, L0, L, L0), v = (-L0/L, 0, -L0/L, 0).
//
// Energy: none conserved - the constraint Phi1 and the spring anchor move
// with time and do work (kHasEnergy = false).
// Reference: the Test Set's published solution at t = 3 (positions, velocities).
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/problem.hpp"
#include "methods/affine.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"

namespace cstab {

struct CarAxisParameters {
  double eps = 1e-2, M = 10, L = 1, L0 = 0.5, r = 0.1, w = 10, g = 1;
  double k() const { return M * eps * eps / 2; }
};

class CarAxisMechanical {
 public:
  static constexpr int kCoords = 4, kHolonomic = 2, kNonholonomic = 0;
  static constexpr bool kHasEnergy = false;
  enum { qXL, qYL, qXR, qYR };

  explicit CarAxisMechanical(const CarAxisParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  static std::vector<ConstraintInfo> constraints() {
    return {{"axle_road", "holonomic (time-dependent)", "xb(t) xl + yb(t) yl (Test Set g1)"},
            {"axle_length", "holonomic", "(xl - xr)^2 + (yl - yr)^2 - L^2 (g2)"}};
  }
  void initial_state(Vec<double, 4>& q, Vec<double, 4>& v) const {
    q << 0, p_.L0, p_.L, p_.L0;
    v << -p_.L0 / p_.L, 0, -p_.L0 / p_.L, 0;
  }
  void to_canonical(double, const Vec<double, 4>& q, const Vec<double, 4>& v, double* c) const {
    for (int i = 0; i < 4; ++i) {
      c[i] = q(i);
      c[4 + i] = v(i);
    }
  }

  template <class S>
  void mass(const S&, const Vec<S, 4>&, Eigen::Matrix<S, 4, 4>& M) const {
    M = Eigen::Matrix<S, 4, 4>::Identity() * S(p_.k());
  }
  template <class S>
  void forces(const S& t, const Vec<S, 4>& q, const Vec<S, 4>&, Vec<S, 4>& Q) const {
    using std::sqrt;
    S xb, yb;
    bump(t, xb, yb);
    const S Ll = sqrt(q(qXL) * q(qXL) + q(qYL) * q(qYL));
    const S dxr = q(qXR) - xb, dyr = q(qYR) - yb;
    const S Lr = sqrt(dxr * dxr + dyr * dyr);
    const double kg = p_.k() * p_.g;
    Q(qXL) = (p_.L0 - Ll) * q(qXL) / Ll;
    Q(qYL) = (p_.L0 - Ll) * q(qYL) / Ll - kg;
    Q(qXR) = (p_.L0 - Lr) * dxr / Lr;
    Q(qYR) = (p_.L0 - Lr) * dyr / Lr - kg;
  }
  template <class S>
  void holonomic(const S& t, const Vec<S, 4>& q, Vec<S, 2>& phi) const {
    S xb, yb;
    bump(t, xb, yb);
    const S dx = q(qXL) - q(qXR), dy = q(qYL) - q(qYR);
    phi(0) = xb * q(qXL) + yb * q(qYL);
    phi(1) = dx * dx + dy * dy - p_.L * p_.L;
  }

  // The same rows with their derivatives in closed form (MechanicalTerms):
  // yb = r sin(w t), xb = sqrt(L^2 - yb^2), so xb' = -yb yb' / xb and
  // xb'' = -(xb'^2 + yb'^2 + yb yb'') / xb.
  template <class Terms>
  void closed_form_holonomic(double t, const Vec<double, 4>& q, const Vec<double, 4>* v, Terms& terms) const {
    double xb, yb;
    bump(t, xb, yb);
    const double yb1 = p_.r * p_.w * std::cos(p_.w * t), xb1 = -yb * yb1 / xb;
    const double dx = q(qXL) - q(qXR), dy = q(qYL) - q(qYR);
    terms.phi(0) = xb * q(qXL) + yb * q(qYL);
    terms.phi(1) = dx * dx + dy * dy - p_.L * p_.L;
    terms.A.template topRows<2>() << xb, yb, 0, 0, 2 * dx, 2 * dy, -2 * dx, -2 * dy;
    terms.phi_t(0) = xb1 * q(qXL) + yb1 * q(qYL);
    terms.phi_t(1) = 0;
    if (v) {
      const double yb2 = -p_.w * p_.w * yb, xb2 = -(xb1 * xb1 + yb1 * yb1 + yb * yb2) / xb;
      const double dvx = (*v)(qXL) - (*v)(qXR), dvy = (*v)(qYL) - (*v)(qYR);
      terms.gamma(0) = xb2 * q(qXL) + yb2 * q(qYL) + 2 * (xb1 * (*v)(qXL) + yb1 * (*v)(qYL));
      terms.gamma(1) = 2 * (dvx * dvx + dvy * dvy);
    }
  }

  template <class S>
  void bump(const S& t, S& xb, S& yb) const {
    using std::sin;
    using std::sqrt;
    yb = p_.r * sin(p_.w * t);
    xb = sqrt(p_.L * p_.L - yb * yb);
  }

 private:
  CarAxisParameters p_;
};

class CarAxis {
 public:
  CarAxis() : mechanical_(params_) {}

  ProblemInfo info() const;
  const CarAxisMechanical& mechanical() const { return mechanical_; }
  // The Test Set's published solution, at t = 3 only.
  bool reference(double t, double* canonical) const;
  static constexpr double kReferenceTime = 3.0;
  static const std::array<double, 8>& published_reference();

 private:
  CarAxisParameters params_;
  CarAxisMechanical mechanical_;
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(CarAxisMechanical);

}  // namespace cstab

// The simple pendulum of the IFToMM multibody benchmark library, problem A01
// (Gonzalez, Dopico, Lugris and Cuadrado 2006, Multibody System Dynamics
// 16:179-190; specification http://lim.ii.udc.es/mbsbenchmark/dist/A01/):
// a point mass m = 1 kg on a massless rod of length L = 1 m pivoted at the
// origin, gravity g = 9.81 N/kg along -y, released at rest with the rod
// horizontal, x = +L, y = 0. The specification integrates 2000 s; cstab's
// default horizon and reference time are 10 s (`--t-end 2000` for its own).
//
// Two formulations:
//  * PendulumMechanical - natural (Cartesian) coordinates q = (x, y),
//    M = m I, Q = (0, -m g), one holonomic row Phi = x^2 + y^2 - L^2,
//    energy E = m |v|^2 / 2 + m g y.
//  * PendulumMinimal - the angle theta from the downward vertical,
//    theta'' = -(g / L) sin theta, x = L sin theta, y = -L cos theta: the
//    reference (GSL rk8pd, rtol = atol = 1e-13, problems/common) and `minimal`.
//
// Problem parameters: `length` (L) and `angle` (theta(0) in degrees; the
// benchmark's 90). Closed forms for the tests: E = -m g L cos theta0 at all
// times, the period 4 sqrt(L / g) K(sin(theta0 / 2)).
#pragma once

#include <string>
#include <vector>

#include "core/params.hpp"
#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"

namespace cstab {

struct PendulumParameters {
  double m = 1.0;       // kg
  double L = 1.0;       // m
  double g = 9.81;      // N/kg, along -y
  double angle = 90.0;  // theta(0), degrees from the downward vertical; at rest
  double theta0() const;  // radians
};

class PendulumMechanical {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;

  explicit PendulumMechanical(const PendulumParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  static std::vector<ConstraintInfo> constraints() {
    return {{"length", "holonomic", "x^2 + y^2 - L^2: the rod keeps its length"}};
  }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const;
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
  template <class S>
  void mass(const S&, const Vec<S, 2>&, Eigen::Matrix<S, 2, 2>& M) const {
    M.setZero();
    M(0, 0) = M(1, 1) = S(p_.m);
  }
  template <class S>
  void forces(const S&, const Vec<S, 2>&, const Vec<S, 2>&, Vec<S, 2>& Q) const {
    Q(0) = S(0.0);
    Q(1) = S(-p_.m * p_.g);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - p_.L * p_.L;
  }
  template <class S>
  S energy(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    return 0.5 * p_.m * v.dot(v) + p_.m * p_.g * q(1);
  }

 private:
  PendulumParameters p_;
};

class PendulumMinimal {
 public:
  static constexpr int kStates = 2;  // theta, theta'

  explicit PendulumMinimal(const PendulumParameters& p) : p_(p) {}

  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return PendulumMechanical::constraints(); }
  void initial_state(Vec<double, 2>& y0) const;
  bool rhs(double t, const Vec<double, 2>& y, Vec<double, 2>& dy) const;
  void to_canonical(double t, const Vec<double, 2>& y, double* c) const;
  void residuals(double t, const Vec<double, 2>& y, double* out) const;

 private:
  PendulumParameters p_;
};

class Pendulum {
 public:
  explicit Pendulum(const PendulumParameters& p = {}) : p_(p), mechanical_(p), minimal_(p) {}

  ProblemInfo info() const;
  std::vector<ParamSpec> problem_params() const;
  Pendulum with_params(const Params& params) const;
  const PendulumMechanical& mechanical() const { return mechanical_; }
  const PendulumMinimal& minimal() const { return minimal_; }
  double energy(double t, const double* canonical) const;
  // Minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;

  const PendulumParameters& parameters() const { return p_; }
  // Closed forms: the energy of every state of the motion, -m g L cos theta0,
  // and the period 4 sqrt(L / g) K(k), k = sin(theta0 / 2) (GSL's complete
  // elliptic integral of the first kind).
  double closed_form_energy() const;
  double period() const;

 private:
  PendulumParameters p_;
  PendulumMechanical mechanical_;
  PendulumMinimal minimal_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 4);
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(PendulumMechanical);

}  // namespace cstab

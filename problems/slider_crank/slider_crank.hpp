// Slider-crank mechanism of the SUNDIALS IDAS example idasSlCrank_dns
// (Serban & Petra; /usr/share/doc/libsundials-dev/examples/idas/serial/).
// Same parameters, forces and initial data as the example:
//
//   q = (q, x, p): crank angle, slider location, connecting-rod angle
//   M = diag(J1, m2, J2),  J1 = 1, m2 = 1, J2 = 2
//   constraints  Phi1 = x - cos p - a cos q = 0,  Phi2 = -sin p - a sin q = 0,  a = 0.5
//   forces: a spring-damper (k = 1, c = 1, free length l0 = 1) between the
//     crank midpoint (a/2)(cos q, sin q) and the rod point (x - cos p / 2, -sin p / 2),
//     and a constant horizontal force F = 1 whose generalized force is
//     (0, F, -F sin p) (the example applies no torque).
//   initial data: q = pi/2, p = asin(-a), x = cos p, all velocities zero.
//
// Energy: there is no conservation law to check. The spring and F are
// conservative (potential k/2 (l - l0)^2 - F (x + cos p)), but the damper
// removes c l'^2 per unit time, so E(t) = E(0) does not hold; E(0) - E(t)
// equals the integral of the dissipation, a quantity of the whole history,
// not of the state. Hence kHasEnergy = false.
//
// Two formulations:
//  * SliderCrankMechanical - the example's 3 coordinates and 2 constraints
//    (M, Q, Phi; every method on mechanical models runs on it).
//  * SliderCrankMinimal - one degree of freedom, the crank angle theta, with
//    p(theta) = -asin(a sin theta), x(theta) = cos p + a cos theta and
//    Lagrange's equation m(theta) theta'' + m'(theta)/2 theta'^2 = Q_theta,
//    derived separately (closed-form derivatives, see slider_crank.cpp). It is
//    the reference solution (GSL rk8pd, rtol = atol = 1e-13) and `minimal`.
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/problem.hpp"
#include "methods/affine.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"
#include "problems/common/trig_rows.hpp"

namespace cstab {

struct SliderCrankParameters {
  double a = 0.5;   // crank length (the example's "half-length of crank")
  double J1 = 1.0;  // crank moment of inertia
  double m2 = 1.0;  // mass on the slider coordinate x
  double J2 = 2.0;  // moment of inertia of the connecting rod
  double k = 1.0;   // spring constant
  double c = 1.0;   // damper constant
  double l0 = 1.0;  // spring free length
  double F = 1.0;   // constant horizontal force
};

// Canonical coordinates: the example's y1..y3 and their rates.
enum SliderCrankCanonical { kScQ, kScX, kScP, kScQd, kScXd, kScPd };

class SliderCrankMechanical {
 public:
  static constexpr int kCoords = 3, kHolonomic = 2, kNonholonomic = 0;
  static constexpr bool kHasEnergy = false;
  enum { qQ, qX, qP };

  explicit SliderCrankMechanical(const SliderCrankParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  static std::vector<ConstraintInfo> constraints() {
    return {{"joint_x", "holonomic", "x - cos p - a cos q: rod end meets crank end (horizontal)"},
            {"joint_y", "holonomic", "-sin p - a sin q: rod end meets crank end (vertical)"}};
  }
  void initial_state(Vec<double, 3>& q, Vec<double, 3>& v) const;
  void to_canonical(double, const Vec<double, 3>& q, const Vec<double, 3>& v, double* c) const {
    for (int i = 0; i < 3; ++i) {
      c[i] = q(i);
      c[3 + i] = v(i);
    }
  }

  template <class S>
  void mass(const S&, const Vec<S, 3>&, Eigen::Matrix<S, 3, 3>& M) const {
    M.setZero();
    M(qQ, qQ) = S(p_.J1);
    M(qX, qX) = S(p_.m2);
    M(qP, qP) = S(p_.J2);
  }
  // The example's force(): spring-damper along l, plus F.
  template <class S>
  void forces(const S&, const Vec<S, 3>& q, const Vec<S, 3>& v, Vec<S, 3>& Q) const {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const double a = p_.a;
    const S s1 = sin(q(qQ)), c1 = cos(q(qQ)), s2 = sin(q(qP)), c2 = cos(q(qP));
    const S x = q(qX);
    const S s21 = s2 * c1 - c2 * s1, c21 = c2 * c1 + s2 * s1;
    const S l2 = x * x - x * (c2 + a * c1) + (1 + a * a) / 4 + a * c21 / 2;
    const S l = sqrt(l2);
    const S ld = (2 * x * v(qX) - v(qX) * (c2 + a * c1) + x * (s2 * v(qP) + a * s1 * v(qQ)) -
                  a * s21 * (v(qP) - v(qQ)) / 2) /
                 (2 * l);
    const S fl = (p_.k * (l - p_.l0) + p_.c * ld) / l;
    Q(qQ) = -fl * a * (s21 / 2 + x * s1) / 2;
    Q(qX) = fl * (c2 / 2 - x + a * c1 / 2) + p_.F;
    Q(qP) = -fl * (x * s2 - a * s21 / 2) / 2 - p_.F * s2;
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 3>& q, Vec<S, 2>& phi) const {
    using std::cos;
    using std::sin;
    phi(0) = q(qX) - cos(q(qP)) - p_.a * cos(q(qQ));
    phi(1) = -sin(q(qP)) - p_.a * sin(q(qQ));
  }
  // The same rows with their derivatives in closed form (MechanicalTerms).
  template <class Terms>
  void closed_form_holonomic(double, const Vec<double, 3>& q, const Vec<double, 3>* v, Terms& terms) const {
    TrigRows<3, 2> rows(q, v);
    const auto P = rows.angle(qP), Q = rows.angle(qQ);
    rows.linear(0, 1.0, qX);
    rows.add_cos(0, -1.0, P);
    rows.add_cos(0, -p_.a, Q);
    rows.add_sin(1, -1.0, P);
    rows.add_sin(1, -p_.a, Q);
    rows.store(terms);
  }

 private:
  SliderCrankParameters p_;
};

class SliderCrankMinimal {
 public:
  static constexpr int kStates = 2;  // theta, theta'

  explicit SliderCrankMinimal(const SliderCrankParameters& p) : p_(p), mech_(p) {}

  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return SliderCrankMechanical::constraints(); }
  void initial_state(Vec<double, 2>& y0) const;
  bool rhs(double t, const Vec<double, 2>& y, Vec<double, 2>& dy) const;
  void to_canonical(double t, const Vec<double, 2>& y, double* c) const;
  void residuals(double t, const Vec<double, 2>& y, double* out) const;

 private:
  SliderCrankParameters p_;
  SliderCrankMechanical mech_;
};

class SliderCrank {
 public:
  SliderCrank() : minimal_(params_), mechanical_(params_) {}

  ProblemInfo info() const;
  const SliderCrankMechanical& mechanical() const { return mechanical_; }
  const SliderCrankMinimal& minimal() const { return minimal_; }
  // Minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;

 private:
  SliderCrankParameters params_;
  SliderCrankMinimal minimal_;
  SliderCrankMechanical mechanical_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 6);
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(SliderCrankMechanical);

}  // namespace cstab

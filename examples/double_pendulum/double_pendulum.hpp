// A problem written outside cstab (docs/plugins.md): the planar double
// pendulum in Cartesian coordinates, two point masses on massless rods,
//     q = (x1, y1, x2, y2),  M = diag(m1, m1, m2, m2),  Q = (0, -m1 g, 0, -m2 g),
//     Phi = (x1^2 + y1^2 - l1^2,  (x2 - x1)^2 + (y2 - y1)^2 - l2^2),
// energy E = m1 |v1|^2 / 2 + m2 |v2|^2 / 2 + g (m1 y1 + m2 y2). Its
// reference is an independent formulation: the two rod angles' equations of
// motion, integrated by cstab's reference cache (GSL rk8pd, 1e-13).
#pragma once

#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"

namespace example {

using cstab::Vec;

struct DoublePendulumParameters {
  double m1 = 1.0, m2 = 1.0;  // kg
  double l1 = 1.0, l2 = 1.0;  // m
  double g = 9.81;            // N/kg, along -y
  double theta1 = 1.0, theta2 = 1.5;  // rad from the downward vertical, at rest
};

class DoublePendulumCartesian {
 public:
  static constexpr int kCoords = 4, kHolonomic = 2, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;

  explicit DoublePendulumCartesian(const DoublePendulumParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  std::vector<cstab::ConstraintInfo> constraints() const {
    return {{"rod1", "holonomic", "x1^2 + y1^2 - l1^2"},
            {"rod2", "holonomic", "(x2 - x1)^2 + (y2 - y1)^2 - l2^2"}};
  }
  void initial_state(Vec<double, 4>& q, Vec<double, 4>& v) const;
  void to_canonical(double, const Vec<double, 4>& q, const Vec<double, 4>& v, double* c) const {
    for (int i = 0; i < 4; ++i) c[i] = q(i), c[4 + i] = v(i);
  }
  template <class S>
  void mass(const S&, const Vec<S, 4>&, Eigen::Matrix<S, 4, 4>& M) const {
    M.setZero();
    M(0, 0) = M(1, 1) = S(p_.m1);
    M(2, 2) = M(3, 3) = S(p_.m2);
  }
  template <class S>
  void forces(const S&, const Vec<S, 4>&, const Vec<S, 4>&, Vec<S, 4>& Q) const {
    Q << S(0.0), S(-p_.m1 * p_.g), S(0.0), S(-p_.m2 * p_.g);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 4>& q, Vec<S, 2>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - p_.l1 * p_.l1;
    phi(1) = (q(2) - q(0)) * (q(2) - q(0)) + (q(3) - q(1)) * (q(3) - q(1)) - p_.l2 * p_.l2;
  }
  template <class S>
  S energy(const S&, const Vec<S, 4>& q, const Vec<S, 4>& v) const {
    return 0.5 * p_.m1 * (v(0) * v(0) + v(1) * v(1)) + 0.5 * p_.m2 * (v(2) * v(2) + v(3) * v(3)) +
           p_.g * (p_.m1 * q(1) + p_.m2 * q(3));
  }

 private:
  DoublePendulumParameters p_;
};

}  // namespace example

// The code every method shares for this model is compiled once, in the
// units `cstab_add_problem(... MODELS example::DoublePendulumCartesian)`
// generates; the pairs declare it extern.
namespace cstab {
CSTAB_EXTERN_MODEL_TEMPLATES(::example::DoublePendulumCartesian);
}  // namespace cstab

namespace example {

// The rod angles (theta1, theta2, theta1', theta2'): the reference's ODE.
class DoublePendulumAngles {
 public:
  static constexpr int kStates = 4;
  explicit DoublePendulumAngles(const DoublePendulumParameters& p) : p_(p) {}
  void initial_state(Vec<double, 4>& y) const { y << p_.theta1, p_.theta2, 0.0, 0.0; }
  void rhs(double t, const Vec<double, 4>& y, Vec<double, 4>& dy) const;
  void to_canonical(double t, const Vec<double, 4>& y, double* c) const;

 private:
  DoublePendulumParameters p_;
};

class DoublePendulum {
 public:
  explicit DoublePendulum(const DoublePendulumParameters& p = {}) : p_(p), model_(p) {}

  cstab::ProblemInfo info() const;
  const DoublePendulumCartesian& mechanical() const { return model_; }
  double energy(double t, const double* canonical) const;
  bool reference(double t, double* canonical) const { return reference_.at(t, canonical); }

 private:
  DoublePendulumParameters p_;
  DoublePendulumCartesian model_;
  cstab::ReferenceCache reference_ = cstab::reference_cache_of(DoublePendulumAngles(p_), 8);
};

}  // namespace example

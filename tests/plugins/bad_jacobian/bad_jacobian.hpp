// A deliberately wrong plugin problem for `cstab check` (tests/plugins):
// a unit pendulum in Cartesian coordinates whose closed-form Jacobian of
// Phi = x^2 + y^2 - 1 is half the true one (x, y instead of 2x, 2y). It
// starts moving (|v| = 1), so the wrong row shows in Phi'' at once.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/vec.hpp"

namespace bad {

using cstab::Vec;

class WrongJacobianModel {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;

  std::string formulation_name() const { return "mechanical"; }
  std::vector<cstab::ConstraintInfo> constraints() const { return {{"length", "holonomic", "x^2 + y^2 - 1"}}; }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << std::sin(1.0), -std::cos(1.0);
    v << std::cos(1.0), std::sin(1.0);  // tangent, |v| = 1
  }
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
  template <class S>
  void mass(const S&, const Vec<S, 2>&, Eigen::Matrix<S, 2, 2>& M) const {
    M.setIdentity();
  }
  template <class S>
  void forces(const S&, const Vec<S, 2>&, const Vec<S, 2>&, Vec<S, 2>& Q) const {
    Q << S(0.0), S(-9.81);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - 1.0;
  }
  template <class S>
  S energy(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    return 0.5 * v.dot(v) + 9.81 * q(1);
  }
  // The closed form, wrong on purpose: J = (x, y).
  template <class Terms>
  void closed_form_holonomic(double, const Vec<double, 2>& q, const Vec<double, 2>* v, Terms& terms) const {
    terms.phi(0) = q(0) * q(0) + q(1) * q(1) - 1.0;
    terms.A(0, 0) = q(0);
    terms.A(0, 1) = q(1);
    terms.phi_t(0) = 0;
    if (v) terms.gamma(0) = 2 * v->dot(*v);
  }
};

class WrongJacobian {
 public:
  cstab::ProblemInfo info() const {
    cstab::ProblemInfo i;
    i.name = "wrong-jacobian";
    i.description = "unit pendulum with a wrong closed-form Jacobian (a test of cstab check)";
    i.coordinates = {"x", "y", "xdot", "ydot"};
    i.formulations = {{"mechanical", "q = (x, y)", model_.constraints()}};
    i.has_energy = true;
    i.default_t_end = 2;
    return i;
  }
  const WrongJacobianModel& mechanical() const { return model_; }
  double energy(double, const double* c) const { return 0.5 * (c[2] * c[2] + c[3] * c[3]) + 9.81 * c[1]; }

 private:
  WrongJacobianModel model_;
};

}  // namespace bad

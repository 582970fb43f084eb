// A correct problem for the compile-fail tests: a unit-mass planar pendulum
// in Cartesian coordinates (q = (x, y), one holonomic row x^2 + y^2 - 1, an
// energy law), with a closed form of its holonomic row, a minimal model
// (the angle) and an affine (state-space) model with a closed-form jet.
// Each test breaks one rule of the contracts in a type derived from these;
// ok_control.cpp checks that they compile as they are.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/vec.hpp"

namespace cstab::compile_fail {

class PendulumModel {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;
  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const { return {{"length", "holonomic", "x^2 + y^2 - 1"}}; }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << std::sin(1.0), -std::cos(1.0);
    v.setZero();
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
    Q(0) = S(0.0);
    Q(1) = S(-9.81);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - 1.0;
  }
  template <class Terms>
  void closed_form_holonomic(double, const Vec<double, 2>& q, const Vec<double, 2>* v, Terms& terms) const {
    terms.phi(0) = q.squaredNorm() - 1.0;
    terms.A.row(0) = 2 * q.transpose();
    terms.phi_t(0) = 0;
    if (v) terms.gamma(0) = 2 * v->squaredNorm();
  }
  template <class S>
  S energy(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    return 0.5 * v.dot(v) + 9.81 * q(1);
  }
};

// The angle from the bottom and its rate.
class PendulumMinimal {
 public:
  static constexpr int kStates = 2;
  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return PendulumModel{}.constraints(); }
  void initial_state(Vec<double, 2>& y) const { y << 1.0, 0.0; }
  bool rhs(double, const Vec<double, 2>& y, Vec<double, 2>& dy) const {
    dy << y(1), -9.81 * std::sin(y(0));
    return true;
  }
  void to_canonical(double, const Vec<double, 2>& y, double* c) const {
    c[0] = std::sin(y(0)), c[1] = -std::cos(y(0));
    c[2] = std::cos(y(0)) * y(1), c[3] = std::sin(y(0)) * y(1);
  }
  void residuals(double, const Vec<double, 2>&, double* out) const { out[0] = 0; }
};

// X = (x, y, xdot, ydot), X' = F + B N, output x^2 + y^2 - 1 (degree 2).
class PendulumStateSpace {
 public:
  static constexpr int kStates = 4, kInputs = 1;
  static constexpr std::array<int, 1> kRelativeDegree = {2};
  std::string formulation_name() const { return "state-space"; }
  std::vector<ConstraintInfo> constraints() const { return PendulumModel{}.constraints(); }
  void initial_state(Vec<double, 4>& X) const { X << std::sin(1.0), -std::cos(1.0), 0.0, 0.0; }
  void to_canonical(double, const Vec<double, 4>& X, double* c) const {
    for (int i = 0; i < 4; ++i) c[i] = X(i);
  }
  template <class S>
  void drift(const S&, const Vec<S, 4>& X, Vec<S, 4>& F) const {
    F << X(2), X(3), S(0.0), S(-9.81);
  }
  void input_matrix(double, const Vec<double, 4>& X, Eigen::Matrix<double, 4, 1>& B) const {
    B << 0.0, 0.0, 2 * X(0), 2 * X(1);
  }
  template <class S>
  void outputs(const S&, const Vec<S, 4>& X, Vec<S, 1>& f) const {
    f(0) = X(0) * X(0) + X(1) * X(1) - 1.0;
  }
  template <class Jet>
  void closed_form_jet(double t, const Vec<double, 4>& X, Jet& jet) const {
    jet.evaluate_ad(*this, t, X);
  }
};

class Pendulum {
 public:
  ProblemInfo info() const {
    ProblemInfo i;
    i.name = "compile-fail-pendulum";
    i.coordinates = {"x", "y", "xdot", "ydot"};
    i.has_energy = true;
    return i;
  }
  const PendulumModel& mechanical() const { return model_; }
  const PendulumMinimal& minimal() const { return minimal_; }
  const PendulumStateSpace& state_space() const { return state_space_; }
  double energy(double, const double* c) const { return 0.5 * (c[2] * c[2] + c[3] * c[3]) + 9.81 * c[1]; }
  bool reference(double, double*) const { return false; }

 private:
  PendulumModel model_;
  PendulumMinimal minimal_;
  PendulumStateSpace state_space_;
};

}  // namespace cstab::compile_fail

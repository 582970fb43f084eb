// The duplicated pendulum of test_redundant.cpp: a planar pendulum in
// Cartesian coordinates whose length constraint appears twice. A problem
// class of the test's own; tests/CMakeLists.txt instantiates every method
// for it (cstab_test_problem_class), one generated unit per method, and its
// model's shared code once (cstab_model).
#pragma once

#include <Eigen/Dense>

#include <cmath>
#include <string>
#include <vector>

#include "core/formulation.hpp"
#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/model_templates.hpp"

namespace cstab {

// q = (x, y), unit mass, length 1, gravity -9.81 y; constraint rows
// x^2 + y^2 - 1 (twice). Energy law 1/2 |v|^2 + g y.
class DuplicatedPendulumModel {
 public:
  static constexpr int kCoords = 2, kHolonomic = 2, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;
  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const {
    return {{"length", "holonomic", "x^2 + y^2 - 1"}, {"length_again", "holonomic", "the same row again"}};
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
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 2>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - 1.0;
    phi(1) = phi(0);
  }
  template <class S>
  S energy(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    return 0.5 * v.dot(v) + 9.81 * q(1);
  }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << std::sin(1.0), -std::cos(1.0);  // 1 rad from the bottom, at rest
    v.setZero();
  }
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
};

// Its shared method code is compiled once, in test_redundant's generated
// model units (cstab_model in tests/CMakeLists.txt).
CSTAB_EXTERN_MODEL_TEMPLATES(DuplicatedPendulumModel);

class DuplicatedPendulum {
 public:
  ProblemInfo info() const {
    ProblemInfo i;
    i.name = "duplicated-pendulum";
    i.coordinates = {"x", "y", "xdot", "ydot"};
    i.has_energy = true;
    i.default_t_end = 2;
    return i;
  }
  const DuplicatedPendulumModel& mechanical() const { return model_; }
  double energy(double, const double* c) const { return 0.5 * (c[2] * c[2] + c[3] * c[3]) + 9.81 * c[1]; }

 private:
  DuplicatedPendulumModel model_;
};

}  // namespace cstab

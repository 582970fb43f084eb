// The Fekete problem of the IVP Test Set (Mazzia, Magherini and Iavernaro,
// Test Set for IVP Solvers, release 2.4, University of Bari; after Bendtsen
// and Thomsen 1999): N charged particles on the unit sphere that repel each
// other with the force of the logarithmic potential and are damped, until
// they come to rest at a Fekete configuration (a local maximum of the
// product of their distances). The Test Set's problem is N = 20 over
// t in [0, 1000], an index-2 DAE of 8N = 160 unknowns (positions p_i,
// velocities q_i, and the multipliers lambda_i, mu_i of its stabilized
// formulation), scored in significant correct digits of the positions at
// t = 1000 against a published RADAU5 solution (rtol = atol = 1e-12).
//
// As a mechanical system: q = (p_1, ..., p_N) in R^3N, M = I, one holonomic
// row per particle |p_i|^2 - 1 = 0, and the force
//     Q_i = sum_(j != i) (p_i - p_j) / |p_i - p_j|^2 - alpha v_i,   alpha = 0.5.
// Its Lyapunov function E = |v|^2 / 2 - sum_(i<j) log |p_i - p_j| decreases
// (dE/dt = -alpha |v|^2): there is no energy law and no first integral.
//
// One formulation, `cartesian`, a runtime-size model (methods/scalable.hpp):
// each row touches its particle's three coordinates only, so the KKT matrix
// is banded whatever N (half-bandwidth 3); the force couples every pair, so
// a right-hand side costs O(N^2).
//
// Starting positions: for N = 20 the Test Set's, four rings of 3, 7, 6 and 4
// particles at latitudes 3 pi/8, pi/8, -2 pi/15, -3 pi/10, at rest. For any
// other N (the parameter, for the scaling study), cstab's own rule: a
// Fibonacci spiral, with latitude and longitude offsets that keep it away
// from equilibrium (docs/problems.md).
//
// Reference: at N = 20 and t = 1000 the Test Set's published solution
// (positions and velocities; the velocities are round-off, about 1e-16);
// at any other N or time, an independent formulation: the same physics as a
// closed-form ODE per particle (the multiplier of each row solved by hand:
// a_i = F_i + lambda_i p_i with lambda_i = -(p_i . F_i + |v_i|^2) / |p_i|^2),
// integrated by GSL rk8pd at rtol = atol = 1e-13.
//
// Problem parameter: N, an integer in [2, 1000].
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/params.hpp"
#include "core/problem.hpp"
#include "methods/scalable.hpp"
#include "problems/common/reference_cache.hpp"

namespace cstab {

struct FeketeParameters {
  int N = 20;
  double alpha = 0.5;  // damping
};

class FeketeCartesian final : public ScalableModel {
 public:
  explicit FeketeCartesian(const FeketeParameters& p) : p_(p) {}
  std::unique_ptr<ScalableModel> clone() const override { return std::make_unique<FeketeCartesian>(*this); }

  std::string formulation_name() const override { return "cartesian"; }
  int coords() const override { return 3 * p_.N; }
  int rows() const override { return p_.N; }
  std::vector<ConstraintGroup> constraint_groups() const override;
  static std::vector<ConstraintInfo> constraints();

  void initial_state(double* q, double* v) const override;
  void to_canonical(double t, const double* q, const double* v, double* c) const override;
  std::vector<Entry> mass() const override;
  void forces(double t, const double* q, const double* v, double* Q) const override;
  void holonomic(const double* q, double* phi) const override;
  std::vector<std::pair<int, int>> jacobian_pattern() const override;
  void jacobian(const double* q, double* values) const override;
  void gamma(const double* q, const double* v, double* gamma) const override;
  bool local_forces() const override { return false; }  // every pair repels

  // The Lyapunov function |v|^2 / 2 - sum_(i<j) log |p_i - p_j|.
  double lyapunov(const double* q, const double* v) const;
  // The independent formulation of the reference: y = (p, v), 6N states.
  void closed_form_rhs(const double* y, double* dydt) const;

 private:
  FeketeParameters p_;
};

class Fekete {
 public:
  explicit Fekete(const FeketeParameters& p = {}) : p_(p), cartesian_(p) {}

  ProblemInfo info() const;
  std::vector<ParamSpec> problem_params() const;
  Fekete with_params(const Params& params) const;
  const FeketeCartesian& scalable() const { return cartesian_; }
  // The Test Set's solution at N = 20, t = 1000; otherwise the closed-form
  // ODE by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;
  // The closed-form ODE's solution at any t (the test of the published one).
  bool ode_reference(double t, double* canonical) const { return reference_.at(t, canonical); }

  const FeketeParameters& parameters() const { return p_; }
  // The Test Set's published positions and velocities at t = 1000 (N = 20),
  // in cstab's canonical order (p_1 .. p_20, then v_1 .. v_20).
  static const std::vector<double>& test_set_solution();
  static constexpr double kTestSetTime = 1000;
  static constexpr double kDefaultHorizon = 20;  // the transient; the Test Set protocol is t = 1000

 private:
  ReferenceCache make_cache() const;

  FeketeParameters p_;
  FeketeCartesian cartesian_;
  ReferenceCache reference_ = make_cache();
};

}  // namespace cstab

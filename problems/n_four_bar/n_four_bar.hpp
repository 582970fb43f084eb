// The N four-bar mechanism of the IFToMM multibody benchmark library, problem
// A02 (Gonzalez, Dopico, Lugris and Cuadrado 2006, Multibody System Dynamics
// 16:179-190; specification http://lim.ii.udc.es/mbsbenchmark/dist/A02/):
// N four-bar loops sharing their bars, 2N + 1 uniform bars of length
// L = 1 m and mass m = 1 kg under gravity g = 9.81 N/kg along -y. N + 1
// cranks A_i B_i turn about the ground points A_i = (i L, 0); N couplers
// B_i B_(i+1) join their tips. The benchmark: N = 40, 20 s, starting from the
// position of its figure (every crank vertical, B_i = (i L, L)) with the x
// velocity of B0 1 m/s; scored on B0's position and velocity, allowed errors
// 1e-1 (low precision) and 1e-3 (high). Every bar horizontal is a singular
// position: the rows lose rank and the mechanism's mobility jumps from 1 to
// N + 1; the motion passes two such positions per turn.
//
// Two formulations:
//  * NFourBarNatural - natural coordinates q = (x_B0, y_B0, ..., x_BN, y_BN),
//    a runtime-size model (methods/scalable.hpp): constant banded mass (a
//    uniform bar between points a and b has kinetic energy
//    m (|va|^2 + va.vb + |vb|^2) / 6; a crank's ground end is fixed), half of
//    each bar's weight at each end, rows |B_i - A_i|^2 - L^2 (cranks) and
//    |B_(i+1) - B_i|^2 - L^2 (couplers).
//  * NFourBarMinimal - the crank angle theta from +x (one degree of freedom:
//    the loops are parallelograms, every crank turns alike and the couplers
//    translate): I theta'' = -W L cos theta with I = m L^2 ((N + 1) / 3 + N),
//    W = m g ((N + 1) / 2 + N). The reference (GSL rk8pd,
//    rtol = atol = 1e-13, problems/common) and `minimal`.
//
// Problem parameter: N, an integer in [1, 1000].
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/params.hpp"
#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/scalable.hpp"
#include "problems/common/reference_cache.hpp"

namespace cstab {

struct NFourBarParameters {
  int N = 40;
  double m = 1.0;      // kg, each bar
  double L = 1.0;      // m, each bar
  double g = 9.81;     // N/kg, along -y
  double speed = 1.0;  // m/s, the initial x velocity of B0
  // The minimal model's constants: I theta'' = -W L cos theta.
  double inertia() const { return m * L * L * ((N + 1) / 3.0 + N); }
  double weight() const { return m * g * ((N + 1) / 2.0 + N); }
};

class NFourBarNatural final : public ScalableModel {
 public:
  explicit NFourBarNatural(const NFourBarParameters& p) : p_(p) {}
  std::unique_ptr<ScalableModel> clone() const override { return std::make_unique<NFourBarNatural>(*this); }

  std::string formulation_name() const override { return "natural"; }
  int coords() const override { return 2 * (p_.N + 1); }
  int rows() const override { return 2 * p_.N + 1; }  // cranks 0..N, then couplers
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
  bool has_energy() const override { return true; }
  double energy(double t, const double* q, const double* v) const override;

 private:
  NFourBarParameters p_;
};

class NFourBarMinimal {
 public:
  static constexpr int kStates = 2;  // theta (from +x), theta'

  explicit NFourBarMinimal(const NFourBarParameters& p) : p_(p) {}

  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return NFourBarNatural::constraints(); }
  void initial_state(Vec<double, 2>& y0) const;
  bool rhs(double t, const Vec<double, 2>& y, Vec<double, 2>& dy) const;
  void to_canonical(double t, const Vec<double, 2>& y, double* c) const;
  void residuals(double t, const Vec<double, 2>& y, double* out) const;

 private:
  NFourBarParameters p_;
};

class NFourBar {
 public:
  explicit NFourBar(const NFourBarParameters& p = {}) : p_(p), natural_(p), minimal_(p) {}

  ProblemInfo info() const;
  std::vector<ParamSpec> problem_params() const;
  NFourBar with_params(const Params& params) const;
  const NFourBarNatural& scalable() const { return natural_; }
  const NFourBarMinimal& minimal() const { return minimal_; }
  double energy(double t, const double* canonical) const;
  // The minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;

  const NFourBarParameters& parameters() const { return p_; }
  int canonical_size() const { return 4 * (p_.N + 1); }

 private:
  NFourBarParameters p_;
  NFourBarNatural natural_;
  NFourBarMinimal minimal_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 4 * (p_.N + 1));
};

}  // namespace cstab

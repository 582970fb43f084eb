// The runtime-size path (issue 19, item 6): mechanical models whose size is
// a problem parameter (n-four-bar's N), and the formulations that run them.
//
// Where the fixed-size models (methods/mechanical.hpp) are templates with
// compile-time sizes and AD derivatives, a scalable model is a class with
// virtual functions and runtime sizes, compiled once, that gives its
// derivatives in closed form with a fixed sparsity:
//   q in R^n (natural coordinates), a constant symmetric positive definite
//   mass matrix M, forces Q(t, q, v), m holonomic scleronomic rows
//   Phi(q) = 0 with J = dPhi/dq (a fixed pattern of entries) and
//   gamma = (dJ/dq v) v, so that the acceleration rows read J a + gamma = 0;
//   the energy law if the model has one.
// Constant mass and time-independent rows are what natural-coordinate
// models of linkages have; a model without them belongs on the fixed path.
//
// The formulations (methods/scalable.cpp) solve the KKT system
//     [ M  J^T ] [ a       ]   [ Q            ]
//     [ J  0   ] [ -lambda ] = [ -gamma - stab ]
// whole, with the unknowns ordered so that each row follows the last
// coordinate it touches: a chain's matrix is then banded, and the band LU
// (linalg/band.hpp) costs O(n) per solve. `kkt = dense` solves the same
// system with a dense LU, O(n^3): the contrast for the scaling study.
// `kGgl` is the stabilized index-2 DAE for SUNDIALS IDA (ida-ggl), with
// the unknowns interleaved in the same order: IDA factors a band matrix
// where the forces are local (DaeSystem::half_bandwidth), dense with
// `kkt = 1`.
// Workspaces are sized at construction; rhs and post_step do not allocate.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/formulation.hpp"
#include "core/params.hpp"

namespace cstab {

// One reported residual: max |Phi_i| over the rows [begin, end).
struct ConstraintGroup {
  ConstraintInfo info;
  int begin = 0, end = 0;
};

class ScalableModel {
 public:
  virtual ~ScalableModel() = default;
  virtual std::unique_ptr<ScalableModel> clone() const = 0;

  virtual std::string formulation_name() const = 0;
  virtual int coords() const = 0;  // n
  virtual int rows() const = 0;    // m holonomic rows
  virtual std::vector<ConstraintGroup> constraint_groups() const = 0;

  virtual void initial_state(double* q, double* v) const = 0;
  virtual void to_canonical(double t, const double* q, const double* v, double* c) const = 0;

  // The constant mass matrix as (row, col, value) entries, both triangles,
  // each position at most once.
  struct Entry {
    int row, col;
    double value;
  };
  virtual std::vector<Entry> mass() const = 0;
  virtual void forces(double t, const double* q, const double* v, double* Q) const = 0;

  virtual void holonomic(const double* q, double* phi) const = 0;
  // J = dPhi/dq: jacobian_pattern gives the (row, col) of each of its
  // entries once; jacobian writes their values in the same order.
  virtual std::vector<std::pair<int, int>> jacobian_pattern() const = 0;
  virtual void jacobian(const double* q, double* values) const = 0;
  // gamma_i = v^T (d^2 Phi_i / dq^2) v.
  virtual void gamma(const double* q, const double* v, double* gamma) const = 0;

  // True if Q_j depends only on the coordinates that share a mass entry or
  // a row with j (a chain's gravity, springs along it): the DAE's iteration
  // matrix is then banded in the KKT order. False if it couples every pair
  // (fekete's charges): IDA then factors it dense.
  virtual bool local_forces() const { return true; }

  virtual bool has_energy() const { return false; }
  virtual double energy(double /*t*/, const double* /*q*/, const double* /*v*/) const { return 0; }
};

// What a method asks of the scalable formulation.
struct ScalableSettings {
  enum class Stabilization { kNone, kBaumgarte, kProjection, kPostStabilization, kGgl };
  Stabilization stabilization = Stabilization::kNone;
  double alpha = 0, beta = 0;  // Baumgarte: Phi'' + 2 alpha Phi' + beta^2 Phi = 0
  double tol = 1e-13;          // projection: stop when max |Phi| <= tol
  int max_iter = 5;            // projection: Gauss-Newton iterations at most
  bool refactor = false;       // post-stabilization: refactor for the velocity correction
  bool dense = false;          // the dense LU instead of the band LU
};

// The `kkt` parameter every method on this path takes: 0 band (default), 1 dense.
ParamSpec scalable_kkt_param();
// Reads `kkt` from params into settings (throws UsageError unless 0 or 1).
void read_scalable_kkt(const Params& params, ScalableSettings& settings);

std::unique_ptr<Formulation> make_scalable_formulation(const ScalableModel& model, const ScalableSettings& settings);

// The KKT ordering's half-bandwidth for a model (the band LU's kl = ku):
// for tests and the scaling section.
int scalable_bandwidth(const ScalableModel& model);

}  // namespace cstab

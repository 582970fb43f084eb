// Velocity projection, a method written outside cstab (docs/plugins.md):
// the index-1 ODE of cstab's `none`, and after every step the velocities
// alone are projected onto the velocity constraints,
//     v <- v - M^-1 A^T (A M^-1 A^T)^-1 (A v + b),
// where A v + b is the velocity-level residual (the holonomic rows' J v +
// Phi_t, then the non-holonomic rows). Positions are left to drift: the
// velocity rows no longer feed it, so it grows slowly instead of
// quadratically (compare `none` and `projection` in a matrix).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "linalg/small_linalg.hpp"
#include "methods/index1.hpp"

namespace example {

template <class Model>
class VelocityProjection final : public cstab::IndexOneFormulation<Model> {
  using Base = cstab::IndexOneFormulation<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);

  explicit VelocityProjection(const Model& model) : Base(model, false, 0.0, 0) {}

  bool has_post_step() const override { return nc > 0; }

  bool post_step(double t, double* y) override {
    if constexpr (nc == 0) {
      return false;
    } else {
      const VecQ q = cstab::vmap<nq>(y);
      auto v = cstab::vmap<nq>(y + nq);
      terms_.evaluate_velocity(this->model_, t, q, VecQ(v));
      this->model_.mass(t, q, M_);
      using Solver = cstab::SchurSolver<nq, nc>;
      if (solver_.factor(M_, terms_.A, 1e-10) != Solver::Status::kOk) {
        this->failure_ = "velocity-projection: singular A M^-1 A^T or M at t = " + std::to_string(t);
        return false;
      }
      v -= solver_.reaction_acceleration(solver_.multipliers(terms_.velocity));
      return true;
    }
  }

 private:
  cstab::MechanicalTerms<Model> terms_;  // fixed-size workspaces: no allocation per step
  Eigen::Matrix<double, nq, nq> M_;
  cstab::SchurSolver<nq, (nc > 0 ? nc : 1)> solver_;
};

struct VelocityProjectionMethod : cstab::MechanicalMethod<VelocityProjectionMethod> {
  static constexpr const char* kName = "velocity-projection";
  static constexpr const char* kDescription =
      "index-1 ODE + after each step v -= M^-1 A^T (A M^-1 A^T)^-1 (A v + b) (example plugin)";
  static std::vector<cstab::ParamSpec> generic_params() { return {}; }
  // A M^-1 A^T by Cholesky: redundant rows (bricard) do not apply, and
  // `cstab list` says why, naming the rank.
  static constexpr bool kNeedsFullRank = true;
  // What `cstab check` holds it to: positions are not corrected, so it does
  // not recover from a start off the manifold; from a consistent one its
  // residual stays below the drift bound (1e-4 by default).
  static cstab::ConformanceSettings conformance() {
    cstab::ConformanceSettings s;
    s.stabilizes = false;
    return s;
  }
  template <class Model>
  static std::unique_ptr<cstab::Formulation> make_model(const Model& model, const cstab::Params&) {
    return std::make_unique<VelocityProjection<Model>>(model);
  }
};

}  // namespace example

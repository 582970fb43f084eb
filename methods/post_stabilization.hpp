// Post-stabilization (Ascher, Chin, Petzold & Reich 1995, "Stabilization of
// constrained mechanical systems with DAEs and invariant manifolds",
// Mech. Struct. Mach. 23:135-157): the index-1 ODE of `none`
// (methods/index1.hpp), and after every step ONE correction
//     y <- y - F(y) h(y),   F = [P_q 0; 0 P_v],   P = M^-1 G^T (G M^-1 G^T)^-1,
// where h = [Phi; velocity residual] and G the constraint rows: the
// holonomic rows J correct positions, q <- q - P_J Phi; all velocity-level
// rows A = [J; G_nonholonomic] correct velocities, v <- v - P_A (A v + [Phi_t; g]).
// Unlike `projection` (methods/index1.hpp) there is no iteration: a single
// Newton-like step is enough, since the integrator keeps the drift at the
// size of its local error and one step squares it (Ascher et al., Sec. 3).
// P is the mass-weighted pseudo-inverse (linalg/weighted_pinv.hpp), so
// redundant rows are handled as in projection.
//   refactor = 0 : F and h at the step's end point, one evaluation of M and
//                  the rows and one factorization serve both corrections
//                  (the paper's F(y) h(y));
//   refactor = 1 : the velocity correction re-evaluates M, the rows and the
//                  velocity residual at the corrected positions (a second
//                  factorization), which is exact for the velocity rows.
// Fixed-size workspaces: no allocation per step.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "methods/index1.hpp"

namespace cstab {

template <class Model>
class PostStabilizationFormulation final : public IndexOneFormulation<Model> {
  using Base = IndexOneFormulation<Model>;

 public:
  using Base::nc;
  using Base::nh;
  using Base::nn;
  using Base::nq;
  using typename Base::VecQ;

  PostStabilizationFormulation(const Model& model, bool refactor)
      : Base(model, false, 0.0, 0), refactor_(refactor) {}

  bool has_post_step() const override { return nc > 0; }

  bool post_step(double t, double* y) override {
    if constexpr (nc == 0) {
      return false;
    } else {
      auto q = vmap<nq>(y);
      auto v = vmap<nq>(y + nq);
      terms_.evaluate_velocity(this->model_, t, VecQ(q), VecQ(v));
      this->model_.mass(t, VecQ(q), M_);
      if (!mass_.factor(M_)) return mass_failure(t);
      VecQ dq = VecQ::Zero();
      if constexpr (nh > 0) {
        pos_pinv_.set_rows(mass_, terms_.A.template topRows<nh>());
        dq = pos_pinv_.correction(terms_.phi);
      }
      if (refactor_) {
        q -= dq;
        terms_.evaluate_velocity(this->model_, t, VecQ(q), VecQ(v));
        this->model_.mass(t, VecQ(q), M_);
        if (!mass_.factor(M_)) return mass_failure(t);
        vel_pinv_.set_rows(mass_, terms_.A);
        v -= vel_pinv_.correction(terms_.velocity);
      } else {
        // Same point, same factorization; with holonomic rows only the
        // velocity rows are the position rows (one decomposition).
        if constexpr (nn == 0) {
          v -= pos_pinv_.correction(terms_.velocity);
        } else {
          vel_pinv_.set_rows(mass_, terms_.A);
          v -= vel_pinv_.correction(terms_.velocity);
        }
        q -= dq;
      }
      return true;
    }
  }

 private:
  bool mass_failure(double t) {
    this->failure_ = "post-stabilization: mass matrix not positive definite at t = " + std::to_string(t);
    return false;
  }

  bool refactor_;
  MechanicalTerms<Model> terms_;
  Eigen::Matrix<double, nq, nq> M_;
  MassFactor<nq> mass_;
  WeightedPinv<(nc > 0 ? nc : 1), nq> vel_pinv_;
  WeightedPinv<(nh > 0 ? nh : 1), nq> pos_pinv_;
};

struct PostStabilizationMethod : MechanicalMethod<PostStabilizationMethod> {
  static constexpr const char* kName = "post-stabilization";
  static constexpr const char* kDescription =
      "index-1 ODE + one post-step correction y -= F h with F from P = M^-1 G^T (G M^-1 G^T)^-1 "
      "(Ascher, Chin, Petzold & Reich 1995)";
  static std::vector<ParamSpec> generic_params() {
    return {{"refactor", 0, Bound::kNonNegative,
             "0: one evaluation and factorization at the step's end point serve both corrections; "
             "1: re-evaluate and refactor at the corrected positions for the velocity correction"}};
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    const double refactor = params.get("refactor");
    if (refactor != 0 && refactor != 1) throw UsageError("--param refactor: must be 0 or 1");
    return std::make_unique<PostStabilizationFormulation<Model>>(model, refactor == 1);
  }
};

}  // namespace cstab

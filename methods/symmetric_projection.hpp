// symmetric-projection: Hairer's symmetric projection (E. Hairer, "Symmetric
// projection methods for differential equations on manifolds", BIT 40
// (2000) 726-734; Hairer, Lubich & Wanner, Geometric Numerical Integration,
// 2nd ed., Sec. V.4.1) around the implicit midpoint rule, for holonomic
// constraints. Its own time-stepping scheme (`--integrator own`).
//
// The ODE is the index-1 one of `none` (methods/index1.hpp): y = [q; v],
// y' = f(t, y) with the accelerations that keep the constraints at the
// acceleration level. Its invariant manifold is g(t, y) = 0 with
//   g = [Phi(t, q); J(t, q) v + Phi_t(t, q)]   (J = dPhi/dq).
// The base method Phi_h is the implicit midpoint rule, symmetric, order 2:
//   z = y + h f(t + h/2, (y + z) / 2), solved by fixed-point iteration.
// A step n -> n+1, with the direction D(t, y) mu = [J^T mu_q; J^T mu_v]:
//   y^ = y_n + D(t_n, y_n) mu                 (leave the manifold)
//   z  = Phi_h(y^)                            (the symmetric base step)
//   y_{n+1} = z + D(t_{n+1}, y_{n+1}) mu      (come back with the same mu)
//   g(t_{n+1}, y_{n+1}) = 0.
// The same mu at both ends, and D at both ends, make the step symmetric
// (its adjoint is itself), so the long-time behaviour of a symmetric method
// survives the projection: for a reversible problem the energy error stays
// bounded where a projection only at the end drifts. mu is found by a
// simplified Newton iteration with the matrix 2 J J^T (the derivative of g
// in mu when Phi_h is near the identity), z recomputed from the new y^ at
// each pass (warm-started), until |g| <= tol (1 + |y|) and the end point
// agrees with the D it was built with.
//
// Parameter symmetric = 0 gives the plain projection around the same base
// step: z = Phi_h(y_n), y_{n+1} = z + D(t_{n+1}, y_{n+1}) mu, g = 0 (the
// standard projection of GNI Sec. IV.4, matrix J J^T). It is there to set
// beside the symmetric one: same base method, same direction, same solves.
//
// D is Euclidean in (q, v), the direction of GNI's algorithm with the
// velocity rows' dependence on q left out (a choice of direction; any D(y)
// gives a symmetric scheme). Where it applies: holonomic constraints of full
// rank (the Newton matrix J J^T is then invertible); M may change with q.
// Non-holonomic rows are refused with the reason.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "core/format.hpp"
#include "linalg/dense.hpp"
#include "methods/consistent_start.hpp"
#include "methods/index1.hpp"
#include "methods/mechanical_method.hpp"
#include "methods/newton_terms.hpp"

namespace cstab {

struct SymmetricProjectionSettings {
  double tol = 1e-12;      // on g and on the fixed points, relative to 1 + |q|, 1 + |v|, 1 + |z|
  int max_iterations = 50; // Newton passes on mu, and fixed-point passes of each midpoint solve
  bool symmetric = true;   // false: the plain projection after the midpoint step
};

template <class Model>
class SymmetricProjectionFormulation final : public SelfSteppingFormulation<Model> {
  using Base = SelfSteppingFormulation<Model>;

 public:
  CSTAB_SELF_STEPPING_MEMBERS(Base);
  static_assert(nn == 0, "symmetric-projection: holonomic constraints only (why_not_model refuses the others)");
  static constexpr int ny = 2 * nq;
  using VecY = Vec<double, ny>;
  using VecH = Vec<double, nh>;
  using MatH = Eigen::Matrix<double, nh, nh>;
  using MatHQ = Eigen::Matrix<double, nh, nq>;

  SymmetricProjectionFormulation(const Model& model, const char* method, const SymmetricProjectionSettings& settings)
      : Base(model, method), f_(model, false, 0.0, 0), settings_(settings) {}

  int dimension() const override { return ny; }

  void initial_state(double* y) const override {
    VecQ q, v;
    ConsistentStart<Model>::state(this->model_, 0.0, q, v);
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
  }

  // Condition number of the Newton matrix J J^T at y.
  bool has_condition_number() const override { return nh > 0; }
  double condition_number(double t, const double* y) override {
    if constexpr (nh > 0) {
      terms_.evaluate_position(this->model_, t, VecQ(vmap<nq>(y)));
      const MatHQ J = terms_.A.template topRows<nh>();
      const MatH S = J * J.transpose();
      return linalg::condition_number(S.data(), nh);
    } else {
      return std::nan("");
    }
  }

  bool advance(double t, double h, double* y) override {
    const double t1 = t + h;
    const VecY yn = vmap<ny>(y);
    // The base step's starting guess: explicit Euler.
    if (!eval(t, yn)) return false;
    z_ = yn + h * fy_;
    if constexpr (nh == 0) {
      if (!midpoint(t, h, yn)) return false;
      count_step(0, true);
      vmap<ny>(y) = z_;
      return true;
    } else {
      terms_.evaluate_position(this->model_, t, VecQ(yn.template head<nq>()));
      J0_ = terms_.A.template topRows<nh>();
      J1_ = J0_;  // the end point's J, first guessed at the start
      mu_q_.setZero();
      mu_v_.setZero();
      const double c = settings_.symmetric ? 2.0 : 1.0;
      double violation = 0, mismatch = 0;
      for (int pass = 0;; ++pass) {
        // The base step from y^ (y_n itself for the plain projection, once).
        if (pass == 0 || settings_.symmetric) {
          yhat_ = yn;
          if (settings_.symmetric) {
            yhat_.template head<nq>() += J0_.transpose() * mu_q_;
            yhat_.template tail<nq>() += J0_.transpose() * mu_v_;
          }
          if (!midpoint(t, h, yhat_)) return false;
        }
        // The end point with the J it is built with; g there.
        q1_ = z_.template head<nq>() + J1_.transpose() * mu_q_;
        v1_ = z_.template tail<nq>() + J1_.transpose() * mu_v_;
        terms_.evaluate_position(this->model_, t1, q1_);
        const MatHQ J = terms_.A.template topRows<nh>();
        rv_ = J * v1_ + terms_.phi_t;
        violation = std::max(terms_.phi.template lpNorm<Eigen::Infinity>() / (1 + q1_.template lpNorm<Eigen::Infinity>()),
                             rv_.template lpNorm<Eigen::Infinity>() / (1 + v1_.template lpNorm<Eigen::Infinity>()));
        // How far the end point is from y_{n+1} = z + D(y_{n+1}) mu with D at it.
        mismatch = std::max(((J - J1_).transpose() * mu_q_).template lpNorm<Eigen::Infinity>() /
                                (1 + q1_.template lpNorm<Eigen::Infinity>()),
                            ((J - J1_).transpose() * mu_v_).template lpNorm<Eigen::Infinity>() /
                                (1 + v1_.template lpNorm<Eigen::Infinity>()));
        J1_ = J;
        if (violation <= settings_.tol && mismatch <= settings_.tol) {
          count_step(pass, true);
          break;
        }
        if (pass == settings_.max_iterations) {
          count_step(pass, false);
          this->failure_ = std::string(method_) + ": the projection (simplified Newton on mu) did not converge in " +
                           std::to_string(pass) + " passes at t = " + format_short(t1) + " (last relative |g| " +
                           format_short(violation) + ")";
          return false;
        }
        const MatH S = c * (J * J.transpose());
        newton_lu_.compute(S.data());
        VecH dq = -terms_.phi, dv = -rv_;
        newton_lu_.solve(dq.data(), dq.data());
        newton_lu_.solve(dv.data(), dv.data());
        if (!dq.allFinite() || !dv.allFinite()) {
          this->failure_ = std::string(method_) + ": singular projection matrix J J^T at t = " + format_short(t1);
          return false;
        }
        mu_q_ += dq;
        mu_v_ += dv;
      }
      // The end point with the final J.
      vmap<nq>(y) = z_.template head<nq>() + J1_.transpose() * mu_q_;
      vmap<nq>(y + nq) = z_.template tail<nq>() + J1_.transpose() * mu_v_;
      return true;
    }
  }

 private:
  // f(t, y) into fy_ (the index-1 ODE); false with the reason if it fails.
  bool eval(double t, const VecY& y) {
    ++evaluations_;
    if (f_.rhs(t, y.data(), fy_.data())) return true;
    this->failure_ = std::string(method_) + ": " + f_.failure_reason();
    return false;
  }

  // The implicit midpoint rule from y0: z_ = y0 + h f(t + h/2, (y0 + z_)/2),
  // by fixed-point iteration from the current z_.
  bool midpoint(double t, double h, const VecY& y0) {
    double change = 0;
    for (int k = 0; k < settings_.max_iterations; ++k) {
      mid_ = 0.5 * (y0 + z_);
      if (!eval(t + 0.5 * h, mid_)) return false;
      next_ = y0 + h * fy_;
      change = (next_ - z_).template lpNorm<Eigen::Infinity>() / (1 + next_.template lpNorm<Eigen::Infinity>());
      z_ = next_;
      if (change <= settings_.tol) return true;
    }
    this->failure_ = std::string(method_) + ": the implicit midpoint step (fixed-point iteration) did not converge in " +
                     std::to_string(settings_.max_iterations) + " passes at t = " + format_short(t + h) +
                     " (last relative change " + format_short(change) + "; a smaller step converges faster)";
    return false;
  }

  IndexOneFormulation<Model> f_;  // the index-1 ODE, no stabilization
  SymmetricProjectionSettings settings_;
  // Workspaces (no allocation per step).
  MechanicalTerms<Model> terms_;
  VecY fy_, z_, mid_, next_, yhat_;
  VecQ q1_, v1_;
  MatHQ J0_, J1_;
  VecH mu_q_, mu_v_, rv_;
  // Dynamic-size LU, compiled once (linalg/dense.cpp): Eigen's fixed-size
  // PartialPivLU cost about 2 s of compile time in every pair.
  linalg::Lu newton_lu_{nh};
};

struct SymmetricProjectionMethod : MechanicalMethod<SymmetricProjectionMethod> {
  static constexpr const char* kName = "symmetric-projection";
  static constexpr bool kNeedsFullRank = true;  // redundant rows: does not apply, naming the rank
  static constexpr MethodKind kKind = MethodKind::kSelfStepping;
  static constexpr const char* kDescription =
      "Hairer's symmetric projection (BIT 2000; GNI V.4.1) around the implicit midpoint rule, for --integrator own: "
      "symmetric, second order; holonomic constraints of full rank (symmetric=0: plain projection after the step)";
  static ConformanceSettings conformance() { return {.integrator = "own", .step = 1e-4, .accuracy_steps = 80000}; }
  static std::vector<ParamSpec> generic_params() {
    return {{"tol", 1e-12, Bound::kPositive,
             "stop the projection when |g| <= tol (1 + |y|), and each midpoint fixed point when z changes by <= tol "
             "(1 + |z|)"},
            ranged_param("iterations", 50, 1, 1000,
                         "Newton passes of the projection, and fixed-point passes of each midpoint solve, per step at "
                         "most (else the run fails)",
                         true),
            ranged_param("symmetric", 1, 0, 1,
                         "1: the symmetric projection (same mu at both ends); 0: the plain projection after the "
                         "midpoint step",
                         true)};
  }

  template <class Model>
  static std::string why_not_model(const Model&) {
    if constexpr (Model::kNonholonomic > 0)
      return std::to_string(Model::kNonholonomic) + " non-holonomic constraint row" +
             (Model::kNonholonomic > 1 ? "s" : "") + ": symmetric-projection is for holonomic constraints only";
    else
      return {};
  }

  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    if constexpr (Model::kNonholonomic > 0) {
      throw UsageError(std::string(kName) + ": " + why_not_model(model));
    } else {
      SymmetricProjectionSettings s;
      s.tol = params.get("tol");
      s.max_iterations = int(params.get("iterations"));
      s.symmetric = params.get("symmetric") != 0;
      return std::make_unique<SymmetricProjectionFormulation<Model>>(model, kName, s);
    }
  }
};

}  // namespace cstab

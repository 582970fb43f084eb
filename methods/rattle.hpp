// rattle: the RATTLE scheme for holonomic constraints (Andersen, "Rattle: a
// 'velocity' version of the Shake algorithm for molecular dynamics
// calculations", J Comput Phys 52 (1983) 24-34; as written in Hairer,
// Lubich & Wanner, Geometric Numerical Integration, 2nd ed., Springer 2006,
// Sec. VII.1.4). Its own time-stepping scheme (a SteppingSystem, run by
// `--integrator own`); symmetric, second order and, for conservative forces
// Q(q), symplectic on the constraint manifold: the energy error stays
// bounded over long times instead of drifting.
//
// Step n -> n+1 of size h, constant M, this suite's sign M a = Q + G^T lambda:
//   v+ = v_n + (h/2) M^-1 (Q(t_n, q_n, v_n) + G(q_n)^T lambda)
//   q1 = q_n + h v+,            Phi(t_{n+1}, q1) = 0          (lambda: Newton)
//   v1 = v+ + (h/2) M^-1 (Q(t_{n+1}, q1, v1) + G(q1)^T mu)
//   G(q1) v1 + Phi_t(t_{n+1}, q1) = 0                           (mu: linear)
// The position equation is solved for lambda by Newton with the Jacobian
// G(q) (h^2/2) M^-1 G(q_n)^T at the current iterate, until |Phi| <= tol
// (1 + |q|). Forces that depend on v (dampers) make the second half-kick
// implicit in v1: fixed-point passes on Q(t_{n+1}, q1, v1), each one linear
// solve for mu, until v1 changes by less than tol (1 + |v1|); when the second
// pass still moves v1, Newton with dQ/dv by AD takes over (stiff dampers,
// where the passes diverge once (h/2) |M^-1 dQ/dv| >= 1).
// Taking Q at v_n in the first half-kick and at v1 in the second is the
// trapezoidal rule in v: the scheme stays symmetric and second order; with
// Q = Q(t, q) it is the textbook RATTLE (one force evaluation a step, the
// second pass only confirms).
//
// Where it applies: holonomic constraints and a constant mass matrix (the
// symplectic structure is that of p = M v). Non-holonomic rows, or an M that
// changes with q or t, are refused before the run with the reason; the
// constant M is checked at the initial state and at two nearby
// configurations and times. Redundant rows are refused with their rank (the
// Newton matrix G M^-1 G^T is then singular).
//
// State: y = [q; v]. Start: q, v made consistent like the DAE methods.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/format.hpp"
#include "linalg/dense.hpp"
#include "linalg/small_linalg.hpp"
#include "methods/consistent_start.hpp"
#include "methods/contracts.hpp"
#include "methods/mechanical_method.hpp"
#include "methods/newton_terms.hpp"

namespace cstab {

struct RattleSettings {
  double tol = 1e-12;  // on Phi (position solve) and on v1 (implicit half-kick), relative to 1 + |q|, 1 + |v|
  int max_iterations = 20;
};

template <class Model>
class RattleFormulation final : public SelfSteppingFormulation<Model> {
  using Base = SelfSteppingFormulation<Model>;

 public:
  CSTAB_SELF_STEPPING_MEMBERS(Base);
  static_assert(nn == 0, "rattle: holonomic constraints only (why_not_model refuses the others)");
  using MatQ = Eigen::Matrix<double, nq, nq>;
  using MatH = Eigen::Matrix<double, nh, nh>;
  using MatQH = Eigen::Matrix<double, nq, nh>;
  using VecH = Vec<double, nh>;
  using MatHQ = Eigen::Matrix<double, nh, nq>;

  RattleFormulation(const Model& model, const char* method, const RattleSettings& settings)
      : Base(model, method), settings_(settings) {
    VecQ q, v;
    model.initial_state(q, v);
    MatQ M;
    model.mass(0.0, q, M);
    mass_pd_ = mass_.factor(M);
  }

  int dimension() const override { return 2 * nq; }

  // The base's Newton counters, and newton_kicks: the steps whose second
  // half-kick needed Newton (forces that depend on v and did not settle in
  // one fixed-point pass).
  std::vector<std::pair<std::string, std::string>> statistics() const override {
    auto out = Base::statistics();
    out.emplace_back("newton_kicks", std::to_string(newton_kicks_));
    return out;
  }

  void initial_state(double* y) const override {
    VecQ q, v;
    ConsistentStart<Model>::state(this->model_, 0.0, q, v);
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
  }

  // Condition number of the position solve's matrix G M^-1 G^T at y.
  bool has_condition_number() const override { return nh > 0; }
  double condition_number(double t, const double* y) override {
    if constexpr (nh > 0) {
      const VecQ q = vmap<nq>(y);
      terms_.evaluate_position(this->model_, t, q);
      const MatH S = terms_.A * minv(MatQH(terms_.A.transpose()));
      return linalg::condition_number(S.data(), nh);
    } else {
      return std::nan("");
    }
  }

  bool advance(double t, double h, double* y) override {
    if (!mass_pd_) {
      this->failure_ = std::string(method_) + ": the mass matrix at t = 0 is not positive definite";
      return false;
    }
    const double t1 = t + h, hh = 0.5 * h;
    const VecQ q_n = vmap<nq>(y), v_n = vmap<nq>(y + nq);
    // First half-kick and drift: q1 = qt + (h^2/2) M^-1 G_n^T lambda.
    this->model_.forces(t, q_n, v_n, Q_);
    ++evaluations_;
    const VecQ vt = v_n + hh * mass_.solve(Q_);
    VecQ q1 = q_n + h * vt;
    VecQ v_half = vt;
    int iterations = 0;
    if constexpr (nh > 0) {
      // G(q_n) and M^-1 G(q_n)^T: the end of the last step's when it is this state.
      const bool continues = have_last_ && t == last_t_ && q_n == last_q_;
      if (!continues) terms_.evaluate_position(this->model_, t, q_n);
      const MatQH MinvGt = continues ? MinvG1t_ : minv(MatQH(terms_.A.transpose()));
      const VecQ qt = q1;
      VecH lambda = VecH::Zero();
      bool converged = false;
      double violation = 0;
      while (true) {
        q1 = qt + (h * hh) * (MinvGt * lambda);
        terms_.evaluate_position(this->model_, t1, q1);
        violation = terms_.phi.template lpNorm<Eigen::Infinity>() / (1 + q1.template lpNorm<Eigen::Infinity>());
        if (violation <= settings_.tol) {
          converged = true;
          break;
        }
        if (iterations == settings_.max_iterations) break;
        ++iterations;
        S_ = (h * hh) * (terms_.A * MinvGt);
        newton_lu_.compute(S_.data());
        VecH dl = -terms_.phi;
        newton_lu_.solve(dl.data(), dl.data());
        if (!dl.allFinite()) break;
        lambda += dl;
      }
      count_step(iterations, converged);
      if (!converged) {
        this->failure_ = std::string(method_) + ": the position solve (Newton on lambda) did not converge in " +
                         std::to_string(iterations) + " iterations at t = " + format_short(t1) +
                         " (last relative |Phi| " + format_short(violation) + ")";
        return false;
      }
      v_half = vt + hh * (MinvGt * lambda);
      // G(q1), Phi_t(t1, q1): the last evaluation. The velocity solve's matrix.
      MinvG1t_ = minv(MatQH(terms_.A.transpose()));
      S_ = terms_.A * MinvG1t_;
      velocity_lu_.compute(S_.data());
    } else {
      count_step(0, true);
    }
    // Second half-kick, implicit in v1 through Q(t1, q1, v1): v1 = F(v1) with
    // F(v) = P(v_half + (h/2) M^-1 Q(t1, q1, v)), P the projection onto
    // G(q1) v + Phi_t = 0. Fixed-point passes while they settle at once (Q
    // independent of v: the second pass confirms); otherwise, from the second
    // pass on, Newton on v - F(v) with the Jacobian I - F'(v), F' = P (h/2)
    // M^-1 dQ/dv taken once (dQ/dv by AD): the fixed-point passes contract
    // only while (h/2) |M^-1 dQ/dv| < 1, which stiff dampers break (the
    // flyball governor at h = 1e-4).
    VecQ v1 = v_half;
    bool converged = false, newton = false;
    double change = 0;
    for (int pass = 0; pass <= settings_.max_iterations; ++pass) {
      this->model_.forces(t1, q1, v1, Q_);
      ++evaluations_;
      VecQ dv = v_half + hh * mass_.solve(Q_);
      if constexpr (nh > 0) {
        VecH r = -(terms_.A * dv + terms_.phi_t);
        velocity_lu_.solve(r.data(), r.data());
        dv += MinvG1t_ * r;
      }
      dv -= v1;
      const double scale = 1 + v1.template lpNorm<Eigen::Infinity>();
      if (pass == 1 && !(dv.template lpNorm<Eigen::Infinity>() <= settings_.tol * scale)) {
        kick_newton_matrix(t1, q1, v1, hh);
        newton = true;
      }
      if (newton) kick_lu_.solve(dv.data(), dv.data());
      v1 += dv;
      change = dv.template lpNorm<Eigen::Infinity>() / (1 + v1.template lpNorm<Eigen::Infinity>());
      if (pass > 0 && change <= settings_.tol) {
        converged = true;
        break;
      }
    }
    newton_kicks_ += newton;
    if (!converged) {
      this->failure_ = std::string(method_) + ": the implicit half-kick (forces at the new velocity) did not converge in " +
                       std::to_string(settings_.max_iterations) + " passes at t = " + format_short(t1) +
                       " (last relative change " + format_short(change) + ")";
      return false;
    }
    vmap<nq>(y) = q1;
    vmap<nq>(y + nq) = v1;
    have_last_ = true;
    last_t_ = t1;
    last_q_ = q1;
    return true;
  }

 private:
  // I - P (h/2) M^-1 dQ/dv at (t1, q1, v1) into kick_lu_, P = I - M^-1 G^T
  // (G M^-1 G^T)^-1 G at q1 (the last position evaluation); dQ/dv by AD,
  // compiled once per model (MechanicalTerms).
  void kick_newton_matrix(double t1, const VecQ& q1, const VecQ& v1, double hh) {
    MechanicalTerms<Model>::force_velocity_jacobian(this->model_, t1, q1, v1, Qv_);
    ++evaluations_;
    MatQ F = hh * minv(Qv_);
    if constexpr (nh > 0) {
      hq_ = terms_.A * F;
      velocity_lu_.solve_columns(hq_.data(), hq_.data(), nq);
      F -= MinvG1t_ * hq_;
    }
    F = MatQ::Identity() - F;
    kick_lu_.compute(F.data());
  }

  // M^-1 B, column by column.
  template <int K>
  Eigen::Matrix<double, nq, K> minv(Eigen::Matrix<double, nq, K> B) const {
    for (int c = 0; c < K; ++c) {
      auto col = B.col(c);
      mass_.solve_lower_in_place(col);
      mass_.solve_upper_in_place(col);
    }
    return B;
  }

  RattleSettings settings_;
  // The constant M = L L^T: fixed-size loops (linalg/small_linalg.hpp);
  // Eigen's fixed-size LLT cost about 2 s of compile time in every pair.
  SmallCholesky<nq> mass_;
  bool mass_pd_ = false;
  // Workspaces (no allocation per step).
  MechanicalTerms<Model> terms_;
  VecQ Q_;
  MatQH MinvG1t_;
  MatH S_;  // the position and velocity solves' matrices
  // Dynamic-size LUs, compiled once (linalg/dense.cpp).
  linalg::Lu newton_lu_{nh}, velocity_lu_{nh};
  MatQ Qv_;
  MatHQ hq_;
  linalg::Lu kick_lu_{nq};
  long newton_kicks_ = 0;  // steps whose half-kick needed Newton
  bool have_last_ = false;
  double last_t_ = 0;
  VecQ last_q_;
};

struct RattleMethod : MechanicalMethod<RattleMethod> {
  static constexpr const char* kName = "rattle";
  static constexpr bool kNeedsFullRank = true;  // redundant rows: does not apply, naming the rank
  static constexpr MethodKind kKind = MethodKind::kSelfStepping;
  static constexpr const char* kDescription =
      "RATTLE (Andersen 1983; Hairer, Lubich & Wanner VII.1.4) for --integrator own: symmetric, second order, "
      "symplectic for conservative forces; holonomic constraints and a constant mass matrix (full rank)";
  // Second order: the same step budget as the generalized-alpha family where
  // the suite checks accuracy.
  static ConformanceSettings conformance() { return {.integrator = "own", .step = 1e-4, .accuracy_steps = 80000}; }
  static std::vector<ParamSpec> generic_params() {
    return {{"tol", 1e-12, Bound::kPositive,
             "position solve: stop when |Phi| <= tol (1 + |q|); implicit half-kick: when v changes by <= tol (1 + |v|)"},
            ranged_param("iterations", 20, 1, 100,
                         "Newton iterations of the position solve, and passes of the half-kick, per step at most "
                         "(else the run fails)",
                         true)};
  }

  // Holonomic rows only, and M(t, q) constant: compared at the initial
  // state and at two nearby configurations and times.
  template <class Model>
  static std::string why_not_model(const Model& model) {
    if constexpr (Model::kNonholonomic > 0) {
      return std::to_string(Model::kNonholonomic) + " non-holonomic constraint row" +
             (Model::kNonholonomic > 1 ? "s" : "") + ": rattle is for holonomic constraints only";
    } else {
      constexpr int nq = Model::kCoords;
      Vec<double, nq> q0, v0;
      model.initial_state(q0, v0);
      Eigen::Matrix<double, nq, nq> M0, M;
      model.mass(0.0, q0, M0);
      const double scale = 1 + M0.template lpNorm<Eigen::Infinity>();
      for (int k = 1; k <= 2; ++k) {
        Vec<double, nq> q = q0;
        for (int i = 0; i < nq; ++i) q(i) += 0.1 * k * (1 + 0.37 * i) * (1 + std::abs(q0(i))) * (i % 2 ? -1 : 1);
        model.mass(0.7 * k, q, M);
        const double change = (M - M0).template lpNorm<Eigen::Infinity>();
        if (!(change <= 1e-12 * scale))
          return "the mass matrix changes with the configuration or time (by " + format_3g(change / scale) +
                 " relative, near the initial state): rattle needs a constant M";
      }
      return {};
    }
  }

  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    if constexpr (Model::kNonholonomic > 0) {
      throw UsageError(std::string(kName) + ": " + why_not_model(model));
    } else {
      const std::string why = why_not_model(model);
      if (!why.empty()) throw UsageError(std::string(kName) + ": " + why);
      RattleSettings s;
      s.tol = params.get("tol");
      s.max_iterations = int(params.get("iterations"));
      return std::make_unique<RattleFormulation<Model>>(model, kName, s);
    }
  }
};

}  // namespace cstab

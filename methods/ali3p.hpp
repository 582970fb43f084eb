// ali3p: the index-3 augmented Lagrangian formulation with velocity and
// acceleration projections on the trapezoidal rule, the scheme behind the
// IFToMM multibody benchmark's reference solutions (Bayo & Ledesma,
// "Augmented Lagrangian and mass-orthogonal projection methods for
// constrained multibody dynamics", Nonlinear Dynamics 9 (1996) 113-130;
// Cuadrado, Cardenal, Morer & Bayo, "Intelligent simulation of multibody
// dynamics: space-state and descriptor methods in sequential and parallel
// computing environments", Multibody Syst Dyn 4 (2000) 55-73). Its own
// time-stepping scheme (a SteppingSystem, run by `--integrator own`).
//
// Step n -> n+1 of size h, trapezoidal rule in terms of q = q_{n+1}:
//   v = (2/h) q + vhat,    vhat = -((2/h) q_n + v_n)
//   a = (4/h^2) q + ahat,  ahat = -((4/h^2) q_n + (4/h) v_n + a_n).
// Equations of motion at t_{n+1} with the augmented Lagrangian multipliers
// (this suite's sign: M a = Q + A^T lambda):
//   f(q) = (h^2/4) [M a - Q - A^T (lambda* - p c)] = 0,
//   c = [Phi(q); (h/2) Psi(q, v)],   lambda*_{i+1} = lambda*_i - p c_{i+1},
// Newton on q with the tangent
//   W = M + (h/2) C + (h^2/4) (K + p A^T A),   A = [Phi_q; dPsi/dv],
// K = d(M a - Q - A^T lambda*)/dq and C = d(...)/dv by AD (the derivative of
// A^T c is left out: c -> 0). One Newton iteration per augmented Lagrangian
// iteration, from the predictor q_n + h v_n + h^2/2 a_n and lambda*_n;
// converged when the correction and c are below the tolerance (relative to
// 1 + |q|). lambda_{n+1} = lambda*.
//
// The penalty p (force per unit violation, Bayo & Ledesma's alpha) is given
// relative to the step's own scale: p = alpha 4 m / (h^2 a), m the largest
// diagonal entry of M, a that of A^T A, so that (h^2/4) p A^T A weighs alpha
// times M in W whatever the units and the step. The iteration contracts the
// constraint violation by about 1/(1 + alpha) per iteration. The published
// fixed values (p = 1e7 to 1e9 for kg-m models at h = 1e-3 to 1e-2) are
// alpha = 2.5 to 2.5e4 here (m = a = 1); a fixed p stalls at small steps
// (measured: p = 1e9 at h = 2.5e-5 on the biped needed more than 50
// iterations in a step at t = 0.0017).
//
// Non-holonomic rows Psi(q, v) = B(q) v + b(q) = 0 join the augmented
// Lagrangian at velocity level, as in Dopico, Gonzalez, Cuadrado & Kovecses,
// "Determination of holonomic and nonholonomic constraint reactions in an
// index-3 augmented Lagrangian formulation with velocity and acceleration
// projections", J Comput Nonlinear Dyn 9 (2014) 041006. Here they enter as
// (h/2) Psi, the position increment they constrain over a half step: their
// derivative in q through v = (2/h) q + vhat is then B, so W holds the same
// A^T A for both kinds of row and is the projections' matrix too.
//
// Mass-orthogonal projections (Cuadrado et al. 2000), with the last Newton
// factorization of W:
//   W (v - v*) = -(h^2/4) p A^T [Phi_q v* + Phi_t; Psi(q, v*)]
//   W (a - a*) = -(h^2/4) p A^T (A a* + gamma)     (A a + gamma = 0)
// where v*, a* are the trapezoidal values. Redundant constraints need no
// special care: W stays regular when A loses rank, and lambda* converges to
// one of the equivalent multiplier sets (the method is known for this).
//
// State: y = [q; v; a; lambda]. Start: q, v made consistent like the DAE
// methods, a and lambda by an augmented Lagrangian iteration on the
// acceleration level (regular with redundant rows too).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/format.hpp"
#include "linalg/dense.hpp"
#include "methods/consistent_start.hpp"
#include "methods/mechanical_method.hpp"
#include "methods/newton_terms.hpp"

namespace cstab {

struct Ali3pSettings {
  double alpha = 1e4;   // penalty factor relative to the step's mass scale
  double tol = 1e-10;   // on the correction and the constraints, relative to 1 + |q|
  int max_iterations = 50;
};

template <class Model>
class Ali3pFormulation final : public SelfSteppingFormulation<Model> {
  using Base = SelfSteppingFormulation<Model>;

 public:
  CSTAB_SELF_STEPPING_MEMBERS(Base);
  static constexpr int kA = 2 * nq, kLambda = 3 * nq, kDim = 3 * nq + nc;
  using MatQ = Eigen::Matrix<double, nq, nq>;
  using VecC = Vec<double, nc>;

  Ali3pFormulation(const Model& model, const char* method, const Ali3pSettings& settings)
      : Base(model, method), settings_(settings) {}

  int dimension() const override { return kDim; }

  void initial_state(double* y) const override {
    VecQ q, v;
    ConsistentStart<Model>::state(this->model_, 0.0, q, v);
    MechanicalTerms<Model> terms;
    terms.evaluate(this->model_, 0.0, q, v, false);
    VecQ a = VecQ::Zero();
    VecC lambda = VecC::Zero();
    if constexpr (nc > 0) {
      // M a = Q + A^T lambda, A a + gamma = 0, by the augmented Lagrangian:
      // (M + p A^T A) a = Q + A^T lambda - p A^T gamma, lambda -= p (A a + gamma).
      const MatQ AtA = terms.A.transpose() * terms.A;
      const double p = 1e3 * terms.M.diagonal().cwiseAbs().maxCoeff() / std::max(AtA.diagonal().maxCoeff(), 1e-300);
      const MatQ W = terms.M + p * AtA;
      linalg::Lu lu(nq);
      lu.compute(W.data());
      for (int it = 0; it < 200; ++it) {
        const VecQ rhs = terms.Q + terms.A.transpose() * lambda - p * terms.A.transpose() * terms.gamma;
        lu.solve(rhs.data(), a.data());
        const VecC viol = terms.A * a + terms.gamma;
        lambda -= p * viol;
        if (viol.template lpNorm<Eigen::Infinity>() <= 1e-15 * (1 + terms.gamma.template lpNorm<Eigen::Infinity>()))
          break;
      }
    } else {
      linalg::Lu lu(nq);
      lu.compute(terms.M.data());
      lu.solve(terms.Q.data(), a.data());
    }
    for (int i = 0; i < kDim; ++i) y[i] = 0;
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
    vmap<nq>(y + kA) = a;
    if constexpr (nc > 0) vmap<nc>(y + kLambda) = lambda;
  }

  // Condition number of W at y for the run's step.
  double condition_number(double t, const double* y) override {
    if (!(step_hint_ > 0)) return std::nan("");
    const double h = step_hint_;
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq), a = vmap<nq>(y + kA);
    VecC lambda = VecC::Zero();
    if constexpr (nc > 0) lambda = vmap<nc>(y + kLambda);
    terms_.evaluate(this->model_, t, q, v, a, lambda);
    iteration_matrix(h);
    return linalg::condition_number(W_.data(), nq);
  }

  bool advance(double t, double h, double* y) override {
    const double t1 = t + h, h2 = 0.25 * h * h;
    const VecQ q_n = vmap<nq>(y), v_n = vmap<nq>(y + nq), a_n = vmap<nq>(y + kA);
    const VecQ vhat = -(2 / h) * q_n - v_n;
    const VecQ ahat = -(4 / (h * h)) * q_n - (4 / h) * v_n - a_n;
    VecQ q = q_n + h * v_n + 0.5 * h * h * a_n;
    VecC lambda = VecC::Zero();
    if constexpr (nc > 0) lambda = vmap<nc>(y + kLambda);
    int it = 0;
    bool converged = false;
    double correction = 0, violation = 0;
    while (it < settings_.max_iterations) {
      ++it;
      ++evaluations_;
      VecQ v = (2 / h) * q + vhat, a = (4 / (h * h)) * q + ahat;
      terms_.evaluate(this->model_, t1, q, v, a, lambda);
      const double p = iteration_matrix(h);
      VecQ f = terms_.r;
      if constexpr (nc > 0) f += p * terms_.A.transpose() * penalty_rows(terms_.phi, terms_.vel, h);
      lu_.compute(W_.data());
      VecQ dq = -h2 * f;
      lu_.solve(dq.data(), dq.data());
      if (!dq.allFinite()) break;
      q += dq;
      correction = dq.template lpNorm<Eigen::Infinity>() / (1 + q.template lpNorm<Eigen::Infinity>());
      violation = 0;
      if constexpr (nc > 0) {
        // The multiplier update with the constraints at the new iterate.
        v = (2 / h) * q + vhat;
        const VecC c = constraint_rows(t1, q, v, h);
        lambda -= p * c;
        violation = c.template lpNorm<Eigen::Infinity>() / (1 + q.template lpNorm<Eigen::Infinity>());
      }
      if (correction <= settings_.tol && violation <= settings_.tol) {
        converged = true;
        break;
      }
    }
    count_step(it, converged);
    if (!converged) {
      this->failure_ = std::string(method_) + ": the augmented Lagrangian iteration did not converge in " +
                       std::to_string(it) + " iterations at t = " + format_short(t1) + " (last relative correction " +
                       format_short(correction) + ", constraints " + format_short(violation) + ")";
      return false;
    }
    VecQ v = (2 / h) * q + vhat, a = (4 / (h * h)) * q + ahat;
    if constexpr (nc > 0) {
      // Mass-orthogonal projections with the last factorization of W.
      projection_terms_.evaluate_velocity(this->model_, t1, q, v);
      VecQ dv = -h2 * p_ * projection_terms_.A.transpose() * projection_terms_.velocity;
      lu_.solve(dv.data(), dv.data());
      v += dv;
      projection_terms_.evaluate(this->model_, t1, q, v, false);
      VecQ da = -h2 * p_ * projection_terms_.A.transpose() * (projection_terms_.A * a + projection_terms_.gamma);
      lu_.solve(da.data(), da.data());
      a += da;
    }
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
    vmap<nq>(y + kA) = a;
    if constexpr (nc > 0) vmap<nc>(y + kLambda) = lambda;
    return true;
  }

 private:
  // c = [Phi; (h/2) Psi] from the holonomic values and the velocity rows.
  static VecC penalty_rows(const Vec<double, nh>& phi, const VecC& vel, double h) {
    VecC c;
    if constexpr (nh > 0) c.template head<nh>() = phi;
    if constexpr (nn > 0) c.template tail<nn>() = 0.5 * h * vel.template tail<nn>();
    return c;
  }

  // c at (t, q, v) from plain evaluations of the model (no derivatives).
  VecC constraint_rows(double t, const VecQ& q, const VecQ& v, double h) const {
    VecC c;
    if constexpr (nh > 0) {
      Vec<double, nh> phi;
      this->model_.holonomic(t, q, phi);
      c.template head<nh>() = phi;
    }
    if constexpr (nn > 0) {
      Vec<double, nn> psi;
      this->model_.nonholonomic(t, q, v, psi);
      c.template tail<nn>() = 0.5 * h * psi;
    }
    return c;
  }

  // W = M + (h/2) C + (h^2/4) (K + p A^T A) at the last evaluate; returns
  // the penalty p = alpha 4 m / (h^2 a) (0 without constraints).
  double iteration_matrix(double h) {
    const double h2 = 0.25 * h * h;
    W_ = terms_.M + 0.5 * h * terms_.C + h2 * terms_.K;
    p_ = 0;
    if constexpr (nc > 0) {
      AtA_.noalias() = terms_.A.transpose() * terms_.A;
      const double m = terms_.M.diagonal().cwiseAbs().maxCoeff(), a = AtA_.diagonal().maxCoeff();
      if (a > 0) p_ = settings_.alpha * m / (h2 * a);
      W_ += h2 * p_ * AtA_;
    }
    return p_;
  }

  Ali3pSettings settings_;
  // Workspaces (no allocation per step).
  NewtonTerms<Model> terms_;
  MechanicalTerms<Model> projection_terms_;
  MatQ W_, AtA_;
  double p_ = 0;  // the penalty of the last iteration matrix
  linalg::Lu lu_{nq};  // dynamic-size, compiled once (linalg/dense.cpp)
};

struct Ali3pMethod : MechanicalMethod<Ali3pMethod> {
  static constexpr const char* kName = "ali3p";
  static constexpr MethodKind kKind = MethodKind::kSelfStepping;
  static constexpr const char* kDescription =
      "index-3 augmented Lagrangian with velocity and acceleration projections on the trapezoidal rule (Bayo & "
      "Ledesma 1996; Cuadrado et al. 2000) for --integrator own; redundant constraints allowed";
  // Second order: the same step budget as the generalized-alpha family where
  // the suite checks accuracy.
  static ConformanceSettings conformance() { return {.integrator = "own", .step = 1e-4, .accuracy_steps = 80000}; }
  static std::vector<ParamSpec> generic_params() {
    return {{"alpha", 1e4, Bound::kPositive,
             "penalty factor, relative to the step's mass scale: p = alpha 4 m / (h^2 a) force per unit violation"},
            ranged_param("iterations", 50, 1, 1000,
                         "augmented Lagrangian (Newton) iterations per step at most (else the run fails)", true),
            {"tol", 1e-10, Bound::kPositive,
             "stop when the correction and the constraints are below this (relative to 1 + |q|)"}};
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    Ali3pSettings s;
    s.alpha = params.get("alpha");
    s.max_iterations = int(params.get("iterations"));
    s.tol = params.get("tol");
    return std::make_unique<Ali3pFormulation<Model>>(model, kName, s);
  }
};

}  // namespace cstab

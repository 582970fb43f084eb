// The generalized-alpha family: implicit second-order schemes that multibody
// codes (Exudyn, Chrono, Simpack, Samcef) ship by default. Each is its own
// time-stepping scheme (a SteppingSystem, run by `--integrator own`), with a
// Newton iteration per step on the mechanical description of
// methods/mechanical.hpp (M a = Q + A^T lambda).
//
//  generalized-alpha     index 3: Arnold & Bruls, "Convergence of the
//      generalized-alpha scheme for constrained mechanical systems", Multibody
//      Syst Dyn 18 (2007) 185-202, Algorithm 1 (equations of motion and
//      Phi(q) = 0 at t_{n+1}; the pseudo-acceleration a carries the alpha
//      recurrence). Coefficients from the spectral radius at infinity rho_inf
//      (Chung & Hulbert 1993): alpha_m = (2 rho - 1)/(rho + 1),
//      alpha_f = rho/(rho + 1), gamma = 1/2 + alpha_f - alpha_m,
//      beta = (gamma + 1/2)^2 / 4.
//  hht                   the same scheme with alpha_m = 0, alpha_f = -alpha,
//      gamma = (1 - 2 alpha)/2, beta = (1 - alpha)^2/4, alpha in [-1/3, 0]
//      (Hilber, Hughes & Taylor 1977 in the generalized-alpha framework;
//      rho_inf = (1 + alpha)/(1 - alpha)).
//  generalized-alpha-i2  stabilized index 2 (GGL-type): the position update
//      gets a correction Phi_q^T nu and the step enforces Phi(q) = 0 and the
//      velocity constraints Phi_q v + Phi_t = 0 together (Arnold, Cardona &
//      Bruls, "A Lie algebra approach to Lie group time integration of
//      constrained systems", in: Betsch (ed), Structure-preserving Integrators
//      in Nonlinear Structural Dynamics and Flexible Multibody Dynamics, CISM
//      565, Springer 2016, section "stabilized index-2 formulation", here in
//      the linear space R^nq: q_{n+1} = q_n + h v_n + h^2 (1/2 - beta) a_n
//      + h^2 beta a_{n+1} + Phi_q^T nu). Phi_q in the correction is taken at
//      the Newton iterate (the derivative of Phi_q^T nu in q is left out of
//      the iteration matrix; nu = O(h^2) vanishes on the exact solution).
//
// Non-holonomic rows Psi(q, v) = 0 are enforced at velocity level at
// t_{n+1} (as Exudyn does), in all three.
//
// Newton: the unknowns are the position increment w (vdot_{n+1} = beta' w,
// v_{n+1} = v_hat + gamma' w, beta' = (1 - alpha_m)/(beta h^2 (1 - alpha_f)),
// gamma' = gamma/(beta h)), the multipliers and nu. The iteration matrix is
// scaled (Bottasso, Bauchau & Cardona, "Time-step-size-independent
// conditioning and sensitivity to perturbations in the numerical solution of
// index three differential algebraic equations", SIAM J Sci Comput 29 (2007)
// 397-414; Negrut, Rampalli, Ottarsson & Sajdak, "On an implementation of
// the HHT method in the context of index 3 DAEs", J Comput Nonlinear Dyn 2
// (2007) 73-85): the equations of motion times beta h^2 (1 - alpha_f)/(1 - alpha_m),
// the multipliers in the same units, the velocity rows times 1/gamma', so that
// every block is O(1) and the condition number stays bounded as h -> 0.
// Its Jacobian comes from AD of the model functions (dQ/dq, dQ/dv, d(M a)/dq
// and d(A^T lambda)/dq through nested duals), never by hand.
//
// State: y = [q; v; a; vdot; lambda; nu] (a: pseudo-acceleration, vdot:
// acceleration, nu only for index 2), so the observables read [q; v] as for
// every mechanical method. Start: q, v made consistent like the DAE methods
// (ConsistentStart, methods/consistent_start.hpp), vdot and lambda from the KKT
// system at t0, a = vdot; `--param consistent_start=0` starts from
// a = vdot = 0, lambda = 0 instead (Arnold & Bruls' order-reduction example).
#pragma once
// Marks the header for the extern declarations of its shared formulation
// (cstab_shared_formulation in methods/CMakeLists.txt).
#define CSTAB_GENERALIZED_ALPHA_HPP

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

struct AlphaCoefficients {
  double alpha_m = 0, alpha_f = 0, gamma = 0.5, beta = 0.25;

  static AlphaCoefficients from_rho_inf(double rho) {
    AlphaCoefficients c;
    c.alpha_m = (2 * rho - 1) / (rho + 1);
    c.alpha_f = rho / (rho + 1);
    c.gamma = 0.5 + c.alpha_f - c.alpha_m;
    c.beta = 0.25 * (c.gamma + 0.5) * (c.gamma + 0.5);
    return c;
  }
  static AlphaCoefficients from_hht_alpha(double alpha) {
    AlphaCoefficients c;
    c.alpha_m = 0;
    c.alpha_f = -alpha;
    c.gamma = 0.5 - alpha;
    c.beta = 0.25 * (1 - alpha) * (1 - alpha);
    return c;
  }
};

struct AlphaSettings {
  AlphaCoefficients coefficients;
  double newton_tol = 1e-10;
  int newton_max_iterations = 10;
  bool consistent_start = true;
};

template <class Model, bool kIndex2>
class GeneralizedAlphaFormulation final : public SelfSteppingFormulation<Model> {
  using Base = SelfSteppingFormulation<Model>;

 public:
  CSTAB_SELF_STEPPING_MEMBERS(Base);
  static constexpr int nm = kIndex2 ? nh : 0;           // nu: the index-2 position correction
  static constexpr int nv = kIndex2 ? nc : nn;          // velocity-level rows in the step
  static constexpr int kA = 2 * nq, kVdot = 3 * nq, kLambda = 4 * nq, kNu = 4 * nq + nc;
  static constexpr int kDim = 4 * nq + nc + nm;
  static constexpr int kN = nq + nc + nm;               // Newton unknowns: w, lambda, nu
  using MatN = Eigen::Matrix<double, kN, kN>;
  using VecN = Vec<double, kN>;

  GeneralizedAlphaFormulation(const Model& model, const char* method, const AlphaSettings& settings)
      : Base(model, method), settings_(settings) {}

  int dimension() const override { return kDim; }

  void initial_state(double* y) const override {
    VecQ q, v;
    ConsistentStart<Model>::state(this->model_, 0.0, q, v);
    Vec<double, nq + nc> x;  // (a, lambda) from the KKT system
    ConsistentStart<Model>::accelerations(this->model_, 0.0, q, v, x);
    for (int i = 0; i < kDim; ++i) y[i] = 0;
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
    if (settings_.consistent_start) {
      vmap<nq>(y + kA) = x.template head<nq>();
      vmap<nq>(y + kVdot) = x.template head<nq>();
      if constexpr (nc > 0) vmap<nc>(y + kLambda) = x.template tail<nc>();
    }
  }

  // Condition number of the (scaled) Newton matrix at y for the run's step.
  double condition_number(double t, const double* y) override {
    if (!(step_hint_ > 0)) return std::nan("");
    const long counted = evaluations_;  // an observation, not a step's work
    const MatN S = newton_matrix(t, y, step_hint_, true);
    evaluations_ = counted;
    return linalg::condition_number(S.data(), kN);
  }

  // The Newton iteration matrix at the state y taken as the iterate of a
  // step of size h ending at t: scaled as the scheme solves it, or unscaled
  // (the plain Jacobian of [M vdot - Q - A^T lambda; Phi; velocity rows] in
  // (w, lambda, nu)). For tests of the conditioning.
  MatN newton_matrix(double t, const double* y, double h, bool scaled) {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq), vdot = vmap<nq>(y + kVdot);
    Vec<double, nc> lambda = Vec<double, nc>::Zero();
    if constexpr (nc > 0) lambda = vmap<nc>(y + kLambda);
    evaluate(t, q, v, vdot, lambda);
    MatN S;
    VecN b;
    assemble(h, S, b);
    if (!scaled) {
      const Scales sc = scales(h);
      // Undo the row scalings, and take lambda rather than s lambda as unknown.
      S.template topRows<nq>() /= sc.s;
      if constexpr (nv > 0) S.template bottomRows<nv>() *= sc.gamma_p;
      if constexpr (nc > 0) S.template middleCols<nc>(nq) *= sc.s;
    }
    return S;
  }

  bool advance(double t, double h, double* y) override {
    const AlphaCoefficients& c = settings_.coefficients;
    const Scales sc = scales(h);
    const double t1 = t + h;
    const VecQ q_n = vmap<nq>(y), v_n = vmap<nq>(y + nq), a_n = vmap<nq>(y + kA), vdot_n = vmap<nq>(y + kVdot);
    // The part of a_{n+1} that does not depend on vdot_{n+1}.
    const VecQ a_known = (c.alpha_f * vdot_n - c.alpha_m * a_n) / (1 - c.alpha_m);
    const VecQ q_hat = q_n + h * v_n + h * h * (0.5 - c.beta) * a_n + h * h * c.beta * a_known;
    const VecQ v_hat = v_n + h * (1 - c.gamma) * a_n + h * c.gamma * a_known;
    // Predictor: vdot_{n+1} = vdot_n, lambda_{n+1} = lambda_n, nu = 0.
    VecQ w = vdot_n / sc.beta_p;
    VecQ q = q_hat + w, v = v_hat + sc.gamma_p * w, vdot = vdot_n;
    Vec<double, nc> lambda = Vec<double, nc>::Zero();
    if constexpr (nc > 0) lambda = vmap<nc>(y + kLambda);
    Vec<double, nm> nu = Vec<double, nm>::Zero();
    int it = 0;
    bool converged = false;
    double correction = 0;
    while (it < settings_.newton_max_iterations) {
      ++it;
      evaluate(t1, q, v, vdot, lambda);
      assemble(h, S_, b_);
      lu_.compute(S_.data());
      lu_.solve(b_.data(), x_.data());
      if (!x_.allFinite()) break;
      const VecQ dw = x_.template head<nq>();
      w += dw;
      VecQ dq = dw;
      if constexpr (nm > 0) {
        const auto dnu = x_.template tail<nm>();
        dq += terms_.A.template topRows<nh>().transpose() * dnu;
        nu += dnu;
      }
      q += dq;
      v = v_hat + sc.gamma_p * w;
      vdot = sc.beta_p * w;
      if constexpr (nc > 0) lambda += x_.template segment<nc>(nq) / sc.s;
      correction = x_.template lpNorm<Eigen::Infinity>() / (1 + q.template lpNorm<Eigen::Infinity>());
      if (correction <= settings_.newton_tol) {
        converged = true;
        break;
      }
    }
    count_step(it, converged);
    if (!converged) {
      this->failure_ = std::string(method_) + ": Newton iteration did not converge in " + std::to_string(it) +
                       " iterations at t = " + format_short(t1) + " (last relative correction " +
                       format_short(correction) + ")";
      return false;
    }
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
    vmap<nq>(y + kA) = a_known + (1 - c.alpha_f) / (1 - c.alpha_m) * vdot;
    vmap<nq>(y + kVdot) = vdot;
    if constexpr (nc > 0) vmap<nc>(y + kLambda) = lambda;
    if constexpr (nm > 0) vmap<nm>(y + kNu) = nu;
    return true;
  }

 private:
  struct Scales {
    double beta_p, gamma_p, s;  // d vdot/dw, d v/dw, the row scale 1/beta_p
  };
  Scales scales(double h) const {
    const AlphaCoefficients& c = settings_.coefficients;
    Scales sc;
    sc.beta_p = (1 - c.alpha_m) / (c.beta * h * h * (1 - c.alpha_f));
    sc.gamma_p = c.gamma / (c.beta * h);
    sc.s = 1 / sc.beta_p;
    return sc;
  }

  void evaluate(double t, const VecQ& q, const VecQ& v, const VecQ& vdot, const Vec<double, nc>& lambda) {
    ++evaluations_;
    terms_.evaluate(this->model_, t, q, v, vdot, lambda);
  }

  // The scaled Newton system S x = b at the last evaluate(), x = (dw, s dlambda, dnu).
  void assemble(double h, MatN& S, VecN& b) const {
    const Scales sc = scales(h);
    S.setZero();
    // Equations of motion times s: s (beta' M + gamma' C + K) dw - A^T (s dlambda) + s K J^T dnu = -s r.
    S.template topLeftCorner<nq, nq>() = terms_.M + sc.s * sc.gamma_p * terms_.C + sc.s * terms_.K;
    b.template head<nq>() = -sc.s * terms_.r;
    if constexpr (nc > 0) S.template block<nq, nc>(0, nq) = -terms_.A.transpose();
    if constexpr (nh > 0) {
      const auto J = terms_.A.template topRows<nh>();
      // Position rows: J (dw + J^T dnu) = -Phi.
      S.template block<nh, nq>(nq, 0) = J;
      b.template segment<nh>(nq) = -terms_.phi;
      if constexpr (nm > 0) {
        S.template block<nq, nm>(0, nq + nc) = sc.s * terms_.K * J.transpose();
        S.template block<nh, nm>(nq, nq + nc) = J * J.transpose();
      }
    }
    if constexpr (nv > 0) {
      // Velocity rows times 1/gamma': (Av/gamma' + A) dw + Av J^T dnu / gamma' = -vel/gamma'.
      constexpr int first = nc - nv;  // index 3: the non-holonomic rows only
      const auto Av = terms_.Av.template bottomRows<nv>();
      S.template block<nv, nq>(nq + nh, 0) = Av / sc.gamma_p + terms_.A.template bottomRows<nv>();
      b.template tail<nv>() = -terms_.vel.template tail<nv>() / sc.gamma_p;
      if constexpr (nm > 0)
        S.template block<nv, nm>(nq + nh, nq + nc) = Av * terms_.A.template topRows<nh>().transpose() / sc.gamma_p;
      (void)first;
    }
  }

  AlphaSettings settings_;
  // Workspaces (no allocation per step).
  NewtonTerms<Model> terms_;
  MatN S_;
  VecN b_, x_;
  linalg::Lu lu_{kN};  // dynamic-size, compiled once (linalg/dense.cpp)
};

// Parameters shared by the three methods.
inline std::vector<ParamSpec> alpha_newton_params() {
  return {{"newton_tol", 1e-10, Bound::kPositive, "Newton: stop when the scaled correction is below this (relative to 1 + |q|)"},
          ranged_param("newton_iterations", 10, 1, 100, "Newton: at most this many iterations per step (else the run fails)", true),
          ranged_param("consistent_start", 1, 0, 1,
                       "1: vdot, lambda from the KKT system at t0 and a = vdot; 0: a = vdot = 0, lambda = 0", true)};
}

inline AlphaSettings alpha_settings(const AlphaCoefficients& c, const Params& params) {
  AlphaSettings s;
  s.coefficients = c;
  s.newton_tol = params.get("newton_tol");
  s.newton_max_iterations = int(params.get("newton_iterations"));
  s.consistent_start = params.get("consistent_start") != 0;
  return s;
}

// What the three methods share: self-stepping, for --integrator own, full
// rank; their parameters are Derived::scheme_param() and the Newton ones,
// and Derived::coefficients(params) sets the scheme.
template <class Derived, bool kIndex2>
struct AlphaMethod : MechanicalMethod<Derived> {
  static constexpr MethodKind kKind = MethodKind::kSelfStepping;
  static constexpr bool kNeedsFullRank = true;  // redundant rows: does not apply, naming the rank
  // Settings of the conformance suite: the own scheme at a step where its
  // O(h^2) error is below the suite's 1e-5 against the references. Second
  // order: at least 80000 steps over the horizon where accuracy is checked
  // (1e-5 against andrews' reference at 0.03 s; hht's energy drift on
  // wheel-sharp, 1.3e-5 at h = 5e-5, 3.2e-6 at 2.5e-5, measured).
  static ConformanceSettings conformance() { return {.integrator = "own", .step = 1e-4, .accuracy_steps = 80000}; }
  static std::vector<ParamSpec> generic_params() {
    std::vector<ParamSpec> p = {Derived::scheme_param()};
    for (auto& s : alpha_newton_params()) p.push_back(s);
    return p;
  }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params& params) {
    return std::make_unique<GeneralizedAlphaFormulation<Model, kIndex2>>(
        model, Derived::kName, alpha_settings(Derived::coefficients(params), params));
  }
};

struct GeneralizedAlphaMethod : AlphaMethod<GeneralizedAlphaMethod, false> {
  static constexpr const char* kName = "generalized-alpha";
  static constexpr const char* kDescription =
      "index-3 generalized-alpha (Arnold & Bruls 2007) for --integrator own: Newton on (q, lambda), scaled "
      "iteration matrix; non-holonomic rows at velocity level (full rank)";
  static ParamSpec scheme_param() {
    return ranged_param("rho_inf", 0.9, 0, 1, "spectral radius at infinite frequency (1: no damping)");
  }
  static AlphaCoefficients coefficients(const Params& params) {
    return AlphaCoefficients::from_rho_inf(params.get("rho_inf"));
  }
};

struct HhtMethod : AlphaMethod<HhtMethod, false> {
  static constexpr const char* kName = "hht";
  static constexpr const char* kDescription =
      "index-3 HHT-alpha in the generalized-alpha framework (alpha_m = 0) for --integrator own (full rank)";
  static ParamSpec scheme_param() {
    return ranged_param("alpha", -0.2, -1.0 / 3.0, 0, "HHT alpha (0: trapezoidal rule; rho_inf = (1 + alpha)/(1 - alpha))");
  }
  static AlphaCoefficients coefficients(const Params& params) {
    return AlphaCoefficients::from_hht_alpha(params.get("alpha"));
  }
};

struct GeneralizedAlphaIndex2Method : AlphaMethod<GeneralizedAlphaIndex2Method, true> {
  static constexpr const char* kName = "generalized-alpha-i2";
  static constexpr const char* kDescription =
      "stabilized index-2 generalized-alpha (Arnold, Cardona & Bruls 2016) for --integrator own: position and "
      "velocity constraints both to Newton tolerance (full rank)";
  // The index-3 method's parameter and coefficients (rho_inf).
  static ParamSpec scheme_param() { return GeneralizedAlphaMethod::scheme_param(); }
  static AlphaCoefficients coefficients(const Params& params) { return GeneralizedAlphaMethod::coefficients(params); }
};

}  // namespace cstab

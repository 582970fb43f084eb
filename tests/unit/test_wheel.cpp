// The wheel-with-pendulum problem (Pesterev, Matrosov, Morozov):
//  - the AD Lie-derivative jet against finite differences,
//  - the minimal model's own consistency (energy, manifold, initial data),
//  - the lambda-feedback law (d/dt + lambda)^r f = 0 on injected residuals,
//  - the state-space formulation against the independent minimal model,
//  - the effect of lambda on the residual.
// Suites named WheelRegression* carry the `regression` label, WheelSlow*
// the `slow` label (tests/CMakeLists.txt); the rest are `unit`.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "harness/integrator.hpp"
#include "harness/run.hpp"
#include "linalg/dense.hpp"
#include "methods/affine.hpp"
#include "methods/minimal.hpp"
#include "methods/pesterev.hpp"
#include "problems/registry.hpp"
#include "problems/wheel/wheel.hpp"
#include "tests/support/expect_close.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

using W = WheelStateSpace;
using X9 = Vec<double, W::kStates>;
using F3 = Vec<double, W::kInputs>;

X9 drift(const W& m, const X9& X) {
  X9 F;
  m.drift(0.0, X, F);
  return F;
}
F3 outputs(const W& m, const X9& X) {
  F3 f;
  m.outputs(0.0, X, f);
  return f;
}
Eigen::Matrix<double, 9, 3> input_matrix(const W& m, const X9& X) {
  Eigen::Matrix<double, 9, 3> B;
  m.input_matrix(0.0, X, B);
  return B;
}

// Derivative of g at X along the fixed vector v: d/ds g(X + s v) at s = 0,
// by the 5-point central stencil on the unit direction (O(eps^4)).
template <class G>
F3 along(const G& g, const X9& X, const X9& v, double eps = 1e-3) {
  const double nv = v.norm();
  if (nv == 0) return F3::Zero();
  const X9 u = v / nv;
  const F3 gp2 = g(X + 2 * eps * u), gp1 = g(X + eps * u), gm1 = g(X - eps * u), gm2 = g(X - 2 * eps * u);
  const F3 d = (-gp2 + 8 * gp1 - 8 * gm1 + gm2) / (12 * eps);
  return d * nv;
}

// A few states: the initial one, one off the manifold, and two along the
// motion (from the minimal model, mapped to state-space coordinates).
std::vector<std::pair<std::string, X9>> sample_states(const Wheel& wheel) {
  std::vector<std::pair<std::string, X9>> out;
  X9 X0;
  wheel.state_space().initial_state(X0);
  out.emplace_back("initial", X0);
  X9 off = X0;
  for (int i = 0; i < 9; ++i) off(i) += 0.02 * std::sin(1.7 * i + 0.3);
  out.emplace_back("off-manifold", off);
  MinimalFormulation<WheelMinimal> minimal(wheel.minimal());
  auto integ = make_integrator("rk8pd", StepSettings{0, 1e-10, 1e-10});
  std::vector<double> y(5);
  minimal.initial_state(y.data());
  integ->start(minimal, 0, y.data());
  for (double t : {0.37, 1.3}) {
    while (integ->t() < t) EXPECT_EQ(integ->step(t), StepOutcome::kOk);
    X9 X;
    minimal.to_canonical(t, integ->y(), X.data());
    out.emplace_back("t=" + std::to_string(t), X);
    X9 off2 = X;
    for (int i = 0; i < 9; ++i) off2(i) += 0.01 * std::cos(2.3 * i + t);
    out.emplace_back("off-manifold near t=" + std::to_string(t), off2);
  }
  return out;
}

// ---------------------------------------------------------------------------
// Lie-derivative jet vs finite differences

TEST(WheelDerivatives, JetMatchesFiniteDifferences) {
  Wheel wheel;
  const W& m = wheel.state_space();
  for (const auto& [label, X] : sample_states(wheel)) {
    SCOPED_TRACE(label);
    LieJet<W> jet;
    jet.evaluate(m, 0.0, X);
    const X9 F = drift(m, X);
    const auto B = input_matrix(m, X);
    EXPECT_EQ((jet.F - F).norm(), 0.0);
    EXPECT_EQ((jet.B - B).norm(), 0.0);

    auto f = [&](const X9& Y) -> F3 { return outputs(m, Y); };
    // L_F f by finite differences along F(Y), as a function of Y.
    auto lf = [&](const X9& Y) -> F3 { return along(f, Y, drift(m, Y)); };

    const F3 f0 = f(X);
    const F3 lf0 = lf(X);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(jet.lower(i, 0), f0(i), 1e-15) << "f_" << i + 1;

    // Output 1 (contact), relative degree 2.
    EXPECT_NEAR(jet.lower(0, 1), lf0(0), 1e-8 * (1 + std::abs(lf0(0)))) << "L_F f1";
    const double top0 = along(lf, X, F)(0);
    EXPECT_NEAR(jet.top(0), top0, 1e-6 * (1 + std::abs(top0))) << "L_F^2 f1";
    for (int j = 0; j < 3; ++j) {
      const double a = along(lf, X, X9(B.col(j)))(0);
      EXPECT_NEAR(jet.A(0, j), a, 1e-6 * (1 + std::abs(a))) << "A(1," << j + 1 << ") = L_B" << j + 1 << " L_F f1";
    }
    // Outputs 2 (rolling) and 3 (tangency), relative degree 1.
    for (int i = 1; i < 3; ++i) {
      EXPECT_NEAR(jet.top(i), lf0(i), 1e-8 * (1 + std::abs(lf0(i)))) << "L_F f" << i + 1;
      for (int j = 0; j < 3; ++j) {
        const double a = along(f, X, X9(B.col(j)))(i);
        EXPECT_NEAR(jet.A(i, j), a, 1e-8 * (1 + std::abs(a))) << "A(" << i + 1 << "," << j + 1 << ")";
      }
      for (int k = 1; k < LieJet<W>::kMaxDegree; ++k) EXPECT_EQ(jet.lower(i, k), 0.0);
    }
  }
}

// The closed-form jet (WheelStateSpace::closed_form_jet, what evaluate
// uses) against the nested-AD jet, on and off the manifold.
TEST(WheelDerivatives, ClosedFormJetMatchesNestedAd) {
  Wheel wheel;
  const W& m = wheel.state_space();
  int compared = 0;
  for (const auto& [label, X] : sample_states(wheel)) {
    SCOPED_TRACE(label);
    LieJet<W> closed, ad;
    closed.evaluate(m, 0.3, X);
    ad.evaluate_ad(m, 0.3, X);
    cstab::testing::expect_matches_ad(closed.F, ad.F, "F");
    cstab::testing::expect_matches_ad(closed.B, ad.B, "B");
    cstab::testing::expect_matches_ad(closed.A, ad.A, "A");
    cstab::testing::expect_matches_ad(closed.top, ad.top, "top");
    cstab::testing::expect_matches_ad(closed.lower, ad.lower, "lower");
    ++compared;
  }
  EXPECT_GE(compared, 6);
}

// The declared relative degrees: f1 does not see the reactions directly
// (L_B f1 = 0) on the tangency manifold, and A is nonsingular there.
TEST(WheelDerivatives, RelativeDegreesHoldOnTheManifold) {
  Wheel wheel;
  const W& m = wheel.state_space();
  for (const auto& [label, X] : sample_states(wheel)) {
    if (label.find("off") != std::string::npos) continue;
    SCOPED_TRACE(label);
    auto f = [&](const X9& Y) -> F3 { return outputs(m, Y); };
    const auto B = input_matrix(m, X);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(along(f, X, X9(B.col(j)))(0), 0.0, 1e-10) << "L_B" << j + 1 << " f1";
    LieJet<W> jet;
    jet.evaluate(m, 0.0, X);
    // Smallest singular value above 1e-3 of the largest.
    EXPECT_LT(linalg::condition_number_of(jet.A), 1e3);
  }
}

// ---------------------------------------------------------------------------
// The minimal model

TEST(WheelMinimalModel, InitialStateMatchesStateSpaceInitialState) {
  // Both are built from the same initial data (contact x, centre xdot) by
  // different routes: tangency/rolling solved in X, geometry of the centre's
  // path in (s, sdot).
  Wheel wheel;
  X9 X0, C;
  wheel.state_space().initial_state(X0);
  Vec<double, 5> y0;
  wheel.minimal().initial_state(y0);
  wheel.minimal().to_canonical(0.0, y0, C.data());
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(C(i), X0(i), 1e-14 * (1 + std::abs(X0(i)))) << "component " << i;
  EXPECT_LT(outputs(wheel.state_space(), X0).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(WheelMinimalModel, ConservesEnergyAndStaysOnTheManifold) {
  Wheel wheel;
  const WheelMinimal& mm = wheel.minimal();
  MinimalFormulation<WheelMinimal> form(mm);
  auto integ = make_integrator("rk8pd", StepSettings{0, 1e-12, 1e-12});
  Vec<double, 5> y;
  form.initial_state(y.data());
  integ->start(form, 0, y.data());
  const double e0 = mm.energy(y);
  X9 C;
  mm.to_canonical(0, y, C.data());
  const double e0_canonical = wheel.energy(0, C.data());
  // The two energy expressions (minimal coordinates vs canonical) agree.
  EXPECT_NEAR(e0_canonical, e0, 1e-13 * std::abs(e0));
  double max_drift = 0, max_res = 0, max_velocity_res = 0, max_energy_mismatch = 0;
  double min_x = 1e9, max_x = -1e9;
  int observed = 0;
  while (integ->t() < 5.0) {
    ASSERT_EQ(integ->step(5.0), StepOutcome::kOk) << integ->failure_reason();
    const Vec<double, 5> yt = Eigen::Map<const Vec<double, 5>>(integ->y());
    max_drift = std::max(max_drift, std::abs(mm.energy(yt) - e0));
    if (integ->steps() % 25 == 0) {
      ++observed;
      mm.to_canonical(integ->t(), yt, C.data());
      max_res = std::max(max_res, outputs(wheel.state_space(), C).cwiseAbs().maxCoeff());
      double r[3];
      mm.residuals(integ->t(), yt, r);
      for (double v : r) max_res = std::max(max_res, std::abs(v));
      // Velocity level of the contact constraint: d f1/dt = L_F f1 when f3 = 0.
      LieJet<W> jet;
      jet.evaluate(wheel.state_space(), integ->t(), C);
      max_velocity_res = std::max(max_velocity_res, std::abs(jet.lower(0, 1)));
      max_energy_mismatch = std::max(max_energy_mismatch, std::abs(wheel.energy(0, C.data()) - mm.energy(yt)));
      min_x = std::min(min_x, C(W::iX));
      max_x = std::max(max_x, C(W::iX));
    }
  }
  EXPECT_GT(observed, 10);
  EXPECT_LT(max_drift, 1e-10 * std::abs(e0)) << "energy drift of the minimal model";
  EXPECT_LT(max_res, 1e-14) << "to_canonical maps onto the constraint manifold";
  EXPECT_LT(max_velocity_res, 1e-13) << "hidden (velocity-level) contact constraint";
  EXPECT_LT(max_energy_mismatch, 1e-12 * std::abs(e0));
  // The paper's description: the centre crosses the local maximum at
  // x ~ -0.13 and ranges over about [-0.67, 0.75] early on.
  EXPECT_LT(min_x, -0.2);
  EXPECT_GT(max_x, 0.6);
}

// ---------------------------------------------------------------------------
// lambda-feedback law on injected residuals

Params pesterev_params(const Wheel& wheel, const std::vector<std::pair<std::string, std::string>>& given) {
  return Params::resolve(PesterevMethod::params(wheel, ""), given, "pesterev");
}

struct Observation {
  double t;
  F3 f;
};

// Integrates the pesterev formulation from X0 (perturbed by `perturb`) and
// returns the outputs at `times`.
std::vector<Observation> feedback_run(const Wheel& wheel, const Params& params,
                                      const std::function<void(X9&)>& perturb, const std::vector<double>& times,
                                      F3* f_initial) {
  PesterevFormulation<W> form(wheel.state_space(), params);
  X9 X;
  form.initial_state(X.data());
  perturb(X);
  form.residuals(0, X.data(), f_initial->data());
  auto integ = make_integrator("rk8pd", StepSettings{0, 1e-13, 1e-13});
  integ->start(form, 0, X.data());
  std::vector<Observation> out;
  for (double t : times) {
    while (integ->t() < t) {
      const auto o = integ->step(t);
      EXPECT_EQ(o, StepOutcome::kOk) << integ->failure_reason();
      if (o != StepOutcome::kOk) return out;
    }
    Observation ob{t, {}};
    form.residuals(t, integ->y(), ob.f.data());
    out.push_back(ob);
  }
  return out;
}

const std::vector<double> kTimes = {0.005, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15};

TEST(WheelLambdaFeedback, ContactResidualFollowsCriticallyDampedLaw) {
  // z + delta moves the contact point off the curve: f1 = delta, and leaves
  // L_F f1 = zdot - p'(x_a) xdot = 0 and f3 (which depends on x_a, alpha
  // only) unchanged. Then (d/dt + lambda)^2 f1 = 0 gives
  // f1 = delta (1 + lambda t) exp(-lambda t).
  Wheel wheel;
  const double lambda = 50, delta = 1e-6;
  F3 f0;
  const auto obs = feedback_run(wheel, pesterev_params(wheel, {{"lambda", "50"}}),
                                [&](X9& X) { X(W::iZ) += delta; }, kTimes, &f0);
  ASSERT_EQ(obs.size(), kTimes.size());
  EXPECT_NEAR(f0(0), delta, 1e-15);
  EXPECT_LT(std::abs(f0(1)), 1e-15);
  EXPECT_LT(std::abs(f0(2)), 1e-15);
  for (const auto& o : obs) {
    const double expected = delta * (1 + lambda * o.t) * std::exp(-lambda * o.t);
    EXPECT_NEAR(o.f(0), expected, 1e-6 * expected + 1e-13) << "t=" << o.t;
    EXPECT_LT(std::abs(o.f(1)), 1e-12) << "t=" << o.t;
    EXPECT_LT(std::abs(o.f(2)), 1e-12) << "t=" << o.t;
  }
}

TEST(WheelLambdaFeedback, RollingResidualDecaysExponentially) {
  // thetadot + delta/r slips the wheel: f2 = delta, f1 and f3 untouched;
  // (d/dt + lambda) f2 = 0 gives f2 = delta exp(-lambda t).
  Wheel wheel;
  const double lambda = 50, delta = 1e-6;
  const double r = wheel.state_space().parameters().r;
  F3 f0;
  const auto obs = feedback_run(wheel, pesterev_params(wheel, {{"lambda", "50"}}),
                                [&](X9& X) { X(W::iTHD) += delta / r; }, kTimes, &f0);
  ASSERT_EQ(obs.size(), kTimes.size());
  EXPECT_NEAR(f0(1), delta, 1e-14);
  for (const auto& o : obs) {
    const double expected = f0(1) * std::exp(-lambda * o.t);
    EXPECT_NEAR(o.f(1), expected, 1e-6 * expected + 1e-13) << "t=" << o.t;
    EXPECT_LT(std::abs(o.f(0)), 1e-12) << "t=" << o.t;
    EXPECT_LT(std::abs(o.f(2)), 1e-12) << "t=" << o.t;
  }
}

TEST(WheelLambdaFeedback, TangencyResidualDecaysExponentially) {
  // alpha + delta tilts the wheel off tangency: f3 != 0 and
  // (d/dt + lambda) f3 = 0 whatever the other outputs do.
  Wheel wheel;
  const double lambda = 50, delta = 1e-6;
  F3 f0;
  const auto obs = feedback_run(wheel, pesterev_params(wheel, {{"lambda", "50"}}),
                                [&](X9& X) { X(W::iALPHA) += delta; }, kTimes, &f0);
  ASSERT_EQ(obs.size(), kTimes.size());
  ASSERT_GT(std::abs(f0(2)), 0.1 * delta);
  for (const auto& o : obs) {
    const double expected = f0(2) * std::exp(-lambda * o.t);
    EXPECT_NEAR(o.f(2), expected, 1e-6 * std::abs(expected) + 1e-13) << "t=" << o.t;
  }
}

TEST(WheelLambdaFeedback, PerOutputLambdas) {
  // lambda_contact and lambda_rolling override lambda for their outputs.
  Wheel wheel;
  const double lc = 20, lr = 80, delta = 1e-6;
  const double r = wheel.state_space().parameters().r;
  F3 f0;
  const auto obs = feedback_run(
      wheel, pesterev_params(wheel, {{"lambda", "50"}, {"lambda_contact", "20"}, {"lambda_rolling", "80"}}),
      [&](X9& X) {
        X(W::iZ) += delta;
        X(W::iTHD) += delta / r;
      },
      kTimes, &f0);
  ASSERT_EQ(obs.size(), kTimes.size());
  for (const auto& o : obs) {
    const double e1 = f0(0) * (1 + lc * o.t) * std::exp(-lc * o.t);
    const double e2 = f0(1) * std::exp(-lr * o.t);
    EXPECT_NEAR(o.f(0), e1, 1e-6 * std::abs(e1) + 1e-13) << "t=" << o.t;
    EXPECT_NEAR(o.f(1), e2, 1e-6 * std::abs(e2) + 1e-13) << "t=" << o.t;
  }
}

TEST(WheelLambdaFeedback, BadLambdaNeverReachesTheFormulation) {
  Wheel wheel;
  EXPECT_THROW(pesterev_params(wheel, {{"lambda", "0"}}), UsageError);
  EXPECT_THROW(pesterev_params(wheel, {{"lambda_rolling", "-1"}}), UsageError);
  EXPECT_THROW(pesterev_params(wheel, {{"lambda_nosuch", "1"}}), UsageError);
}

// ---------------------------------------------------------------------------
// Against the independent minimal-coordinate model (regression)

RunConfig wheel_config(const std::string& method, const std::string& integrator, StepSettings s, double t_end) {
  return testing::quiet_run_config("wheel", method, integrator, s, t_end);
}

TEST(WheelRegression, PesterevMatchesMinimalModel) {
  const Problem& problem = find_problem("wheel");
  RunConfig c = wheel_config("pesterev", "rk8pd", StepSettings{0, 1e-12, 1e-12}, 5);
  const RunResult r = run_case(problem, c, "");
  ASSERT_EQ(r.status, "ok") << r.reason;
  EXPECT_EQ(r.formulation, "state-space");
  EXPECT_EQ(r.ref_time, 5);
  EXPECT_LE(r.ref_error, 1e-8);
  ASSERT_EQ(r.state_at_ref.size(), 9u);
  ASSERT_EQ(r.ref_state.size(), 9u);
  const auto& names = problem.info().coordinates;
  for (size_t i = 0; i < 9; ++i)
    EXPECT_NEAR(r.state_at_ref[i], r.ref_state[i], 1e-8 * (1 + std::abs(r.ref_state[i]))) << names[i];
  // A tight run keeps every constraint and the energy at round-off level.
  for (const auto& cm : r.constraints) EXPECT_LT(cm.max_abs, 1e-12) << cm.name;
  EXPECT_LT(r.max_energy_drift, 1e-10);
}

TEST(WheelRegression, ReferenceAgreesWithOtherIntegrators) {
  // The reference (minimal model, rk8pd 1e-13) against the minimal model
  // through msadams and the state-space model through rk4 with a small step.
  const Problem& problem = find_problem("wheel");
  std::vector<double> ref(9);
  ASSERT_TRUE(problem.reference(5.0, ref.data()));
  const RunResult a = run_case(problem, wheel_config("minimal", "msadams", StepSettings{0, 1e-12, 1e-12}, 5), "");
  ASSERT_EQ(a.status, "ok") << a.reason;
  const RunResult b = run_case(problem, wheel_config("pesterev", "rk4", StepSettings{2e-4, 0, 0}, 5), "");
  ASSERT_EQ(b.status, "ok") << b.reason;
  for (size_t i = 0; i < 9; ++i) {
    EXPECT_NEAR(a.final_state[i], ref[i], 1e-7 * (1 + std::abs(ref[i]))) << "minimal/msadams " << i;
    EXPECT_NEAR(b.final_state[i], ref[i], 1e-6 * (1 + std::abs(ref[i]))) << "pesterev/rk4 " << i;
  }
}

TEST(WheelRegression, LargerLambdaDampsAccumulatedDrift) {
  // Far below the step's stability limit (lambda h << 1), the residual is
  // accumulated truncation error, which feedback damps: with lambda -> 0 it
  // grows like t^2 for the contact (relative degree 2). Over [0, 20] with
  // rk4, h = 1e-3 the maximum residual falls as lambda grows 0.01 -> 0.1 -> 1.
  const Problem& problem = find_problem("wheel");
  std::vector<double> res;
  for (const char* lambda : {"0.01", "0.1", "1"}) {
    RunConfig c = wheel_config("pesterev", "rk4", StepSettings{1e-3, 0, 0}, 20);
    c.params = {{"lambda", lambda}};
    const RunResult r = run_case(problem, c, "");
    ASSERT_EQ(r.status, "ok") << r.reason;
    res.push_back(r.max_residual);
  }
  EXPECT_GT(res[0], 2 * res[1]) << res[0] << " vs " << res[1];
  EXPECT_GT(res[1], 2 * res[2]) << res[1] << " vs " << res[2];
}

TEST(WheelRegression, LargeLambdaNeedsASmallStep) {
  // lambda = 1500 with rk4: at h = 1e-3 (lambda h = 1.5, inside the
  // stability interval but far from resolving exp(-lambda h)) the residual is
  // dominated by the lambda-amplified truncation error and is *larger* than
  // with lambda = 1; at h = 1e-5 (the paper's step) it is at round-off level.
  const Problem& problem = find_problem("wheel");
  auto run = [&](const char* lambda, double h) {
    RunConfig c = wheel_config("pesterev", "rk4", StepSettings{h, 0, 0}, 2);
    c.params = {{"lambda", lambda}};
    const RunResult r = run_case(problem, c, "");
    EXPECT_EQ(r.status, "ok") << r.reason;
    return r.max_residual;
  };
  const double coarse_small = run("1", 1e-3), coarse_large = run("1500", 1e-3);
  const double mid_large = run("1500", 1e-4);
  EXPECT_GT(coarse_large, 10 * coarse_small);
  EXPECT_LT(mid_large, 1e-3 * coarse_large);  // converges like h^4 or faster
}

TEST(WheelRegression, PaperSettingsShortHorizon) {
  // The paper's method and step (Adams, h = 1e-5, lambda = 1500) over the
  // first second: residuals below its 5e-10, energy deviation below 2e-8.
  const Problem& problem = find_problem("wheel");
  RunConfig c = wheel_config("pesterev", "adams", StepSettings{1e-5, 0, 0}, 1);
  const RunResult r = run_case(problem, c, "");
  ASSERT_EQ(r.status, "ok") << r.reason;
  EXPECT_LT(r.max_residual, 5e-10);
  EXPECT_LT(r.max_energy_drift, 2e-8);
}

TEST(WheelSlow, PaperRunFullHorizon) {
  // The paper's whole run: Adams, h = 1e-5, lambda = 1500 on [0, 200].
  const Problem& problem = find_problem("wheel");
  RunConfig c = wheel_config("pesterev", "adams", StepSettings{1e-5, 0, 0}, 200);
  c.observe_every = 100;
  const RunResult r = run_case(problem, c, "");
  ASSERT_EQ(r.status, "ok") << r.reason;
  EXPECT_LT(r.max_residual, 5e-10);
  EXPECT_LT(r.max_energy_drift, 2e-8);
}

}  // namespace
}  // namespace cstab

// cstab stability (harness/stability.hpp): the measured boundary against
// linear theory where there is one, and the step boundary of the schemes
// and parameters that have none.
//
// A gain on RK4: Pesterev's feedback makes the position residual obey
// (d/dt + lambda)^2 Phi = 0, and the penalty formulation (critically damped,
// xi = 1) makes it obey (d/dt + omega)^2 Phi = 0 up to the mass term
// m / (m + p a) (1e-4 at its default factor). So a fixed-step RK4 run blows
// up once h * rate leaves RK4's real stability interval, [0, 2.785]. On the
// pendulum hanging at rest, started 1e-9 off the manifold, nothing else
// moves: the measured boundary is the theory's (the Jordan block's
// transient, N z R'(-z) R(-z)^(N-1), is too small at that start to reach
// the blow-up threshold inside the interval).

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/stability.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"

using namespace cstab;

namespace {

StabilityConfig pendulum_at_rest(const std::string& method, const std::string& gain) {
  StabilityConfig c;
  c.base.problem = "pendulum";
  c.base.problem_params = {{"angle", "0"}};
  c.base.method = method;
  c.base.integrator = "rk4";
  c.base.t_end = 1;
  c.base.perturb = 1e-9;
  c.base.blowup = 1;
  c.gain_param = gain;
  c.steps = {1e-3};
  c.gains = {100, 1000, 3000, 1e4};
  c.bisection_iterations = 14;
  return c;
}

}  // namespace

TEST(StabilityBoundary, Rk4IntervalFromItsPolynomial) {
  // |R(-x)| = 1 at x = 2.7852935634 for R(w) = 1 + w + w^2/2 + w^3/6 + w^4/24.
  EXPECT_NEAR(real_stability_boundary("rk4"), 2.7852935634, 1e-8);
  EXPECT_NEAR(real_stability_boundary("euler"), 2.0, 1e-9);
  EXPECT_EQ(real_stability_boundary("rk8pd"), 0);
}

// The measured boundary of `method`'s gain on RK4, as h * rate over RK4's
// real stability interval.
double rk4_boundary_ratio(const std::string& method, const std::string& gain) {
  const auto cfg = pendulum_at_rest(method, gain);
  const Problem& problem = find_problem("pendulum");
  EXPECT_TRUE(boundary_in_rate(gain_spec(problem, cfg), "rk4"));
  const auto b = stability_boundaries(problem, cfg);
  if (b.size() != 1u) return NAN;
  EXPECT_LT(b[0].stable_rate, b[0].unstable_rate);
  return b[0].measured / b[0].theory;
}

TEST(StabilityBoundary, PesterevOnRk4MatchesTheInterval) {
  EXPECT_NEAR(rk4_boundary_ratio("pesterev", "lambda"), 1.0, 0.01);
}

// The gain map of issue 17's penalty method: its rate omega, the same
// interval.
TEST(StabilityBoundary, PenaltyOnRk4MatchesTheInterval) {
  EXPECT_NEAR(rk4_boundary_ratio("penalty", "omega"), 1.0, 0.01);
}

// A parameter that is not a gain (rho_inf), or a scheme with no real
// stability interval (--integrator own): the boundary is in the step. Its
// bracket must hold what the runs say: the stable end runs ok, the unstable
// end does not, every grid step below the stable end ran ok, and a value
// whose grid is stable throughout has no unstable end. Explicit Euler on
// Baumgarte's gain, swept as a setting would be, is the check with a
// closed form: at alpha = beta (double root -alpha) it blows up once
// h alpha > 2, so the largest stable step at alpha = 1000 is 2 ms. Just
// beyond it the residual grows by |1 - h alpha| a step: over 10 s (5000
// steps) from 1e-9 to the threshold 1 takes h alpha > 2 (1 + 0.004), the
// resolution of the check.
TEST(StepBoundary, BracketsWhatTheRunsSay) {
  StabilityConfig cfg;
  cfg.base.problem = "wheel";
  cfg.base.method = "hht";
  cfg.base.integrator = "own";
  cfg.base.t_end = 1;
  cfg.gain_param = "alpha";
  cfg.steps = {1e-3, 1e-2, 1e-1, 0.3};
  cfg.gains = {-1.0 / 3.0, 0};
  cfg.bisection_iterations = 6;
  const Problem& problem = find_problem("wheel");
  ASSERT_FALSE(boundary_in_rate(gain_spec(problem, cfg), "own"));
  const auto map = stability_map(problem, cfg);
  ASSERT_EQ(map.size(), cfg.steps.size() * cfg.gains.size());
  const auto bounds = step_boundaries(problem, cfg, map);
  ASSERT_EQ(bounds.size(), cfg.gains.size());
  int bisected = 0;
  for (const auto& b : bounds) {
    SCOPED_TRACE("alpha = " + std::to_string(b.gain));
    ASSERT_TRUE(std::isfinite(b.stable_step)) << "no stable step on the grid";
    for (const auto& p : map) {
      if (p.gain == b.gain && p.step <= b.stable_step) {
        EXPECT_EQ(p.status, "ok") << "h = " << p.step;
      }
    }
    if (std::isnan(b.unstable_step)) {
      EXPECT_EQ(b.stable_step, 0.3);
      continue;
    }
    EXPECT_LT(b.stable_step, b.unstable_step);
    EXPECT_LE(b.unstable_step / b.stable_step, std::pow(10.0, 1.0 / 64) * 1.0001);  // 6 halvings of <= 1 decade
    RunConfig at = cfg.base;
    at.write_series = false;
    at.step.step = b.stable_step;
    apply_gain(at, gain_spec(problem, cfg), b.gain);
    EXPECT_EQ(run_case(problem, at, "").status, "ok");
    at = cfg.base;
    at.write_series = false;
    at.step.step = b.unstable_step;
    apply_gain(at, gain_spec(problem, cfg), b.gain);
    EXPECT_NE(run_case(problem, at, "").status, "ok");
    ++bisected;
  }
  // On the wheel over 1 s both values fail their Newton iteration at
  // h = 0.1 (measured: largest stable steps 0.078 and 0.090).
  EXPECT_EQ(bisected, 2);
}

TEST(StepBoundary, EulerOnBaumgarteAgainstItsClosedForm) {
  StabilityConfig cfg;
  cfg.base.problem = "pendulum";
  cfg.base.problem_params = {{"angle", "0"}};
  cfg.base.method = "baumgarte";
  cfg.base.integrator = "euler";
  cfg.base.t_end = 10;
  cfg.base.perturb = 1e-9;
  cfg.base.blowup = 1;
  cfg.base.params = {{"alpha", "1000"}, {"beta", "1000"}};
  cfg.gain_param = "gamma";  // not the gain: swept as a setting, the boundary is in the step
  cfg.steps = {1e-4, 1e-3, 1e-2};
  cfg.gains = {1000};
  cfg.bisection_iterations = 14;
  const Problem& problem = find_problem("pendulum");
  ASSERT_FALSE(boundary_in_rate(gain_spec(problem, cfg), "euler"));
  const auto bounds = step_boundaries(problem, cfg, stability_map(problem, cfg));
  ASSERT_EQ(bounds.size(), 1u);
  EXPECT_GT(bounds[0].stable_step / 2e-3, 0.995) << bounds[0].stable_step;
  EXPECT_LT(bounds[0].stable_step / 2e-3, 1.006) << bounds[0].stable_step;
}

// Redundant constraints: a planar pendulum in Cartesian coordinates whose
// length constraint appears twice (two identical rows). Braun-Goldfarb and
// projection use rank-revealing pseudo-inverses and must run; every method
// that needs full-rank rows must stop before running with an error naming
// the redundancy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "harness/run.hpp"
#include "tests/unit/duplicated_pendulum.hpp"

namespace cstab {

// Every method for the test's class, generated (tests/CMakeLists.txt).
std::unique_ptr<Problem> cstab_adapt_DuplicatedPendulum(DuplicatedPendulum problem);

namespace {

RunConfig config(const std::string& method, const std::string& integrator) {
  RunConfig cfg;
  cfg.problem = "duplicated-pendulum";
  cfg.method = method;
  cfg.integrator = integrator;
  cfg.t_end = 2;
  cfg.ref_time = 0;
  cfg.write_series = false;
  if (integrator == "rk4" || integrator == "own") cfg.step.step = 1e-3;
  else cfg.step.rtol = cfg.step.atol = 1e-10;
  return cfg;
}

const Problem& problem() {
  static const std::unique_ptr<Problem> p = cstab_adapt_DuplicatedPendulum(DuplicatedPendulum{});
  return *p;
}

TEST(RedundantConstraints, PseudoInverseMethodsRun) {
  for (const auto& [method, integrator, params] :
       std::vector<std::tuple<std::string, std::string, std::vector<std::pair<std::string, std::string>>>>{
           {"braun-goldfarb", "rk4", {{"dt", "1e-2"}}},
           {"projection", "rk8pd", {}},
           {"none", "rk8pd", {}}}) {
    RunConfig cfg = config(method, integrator);
    cfg.params = params;
    const RunResult r = run_case(problem(), cfg, "");
    ASSERT_EQ(r.status, "ok") << method << ": " << r.reason;
    EXPECT_LT(r.max_residual, method == "none" ? 1e-6 : 1e-7) << method;
    EXPECT_LT(r.max_energy_drift, 1e-5) << method;
    // The final state is still on the circle.
    ASSERT_EQ(r.final_state.size(), 4u);
    EXPECT_NEAR(r.final_state[0] * r.final_state[0] + r.final_state[1] * r.final_state[1], 1.0, 1e-7);
  }
}

// The index-3 augmented Lagrangian is known for running on redundant rows:
// its iteration matrix M + (h/2) C + (h^2/4)(K + alpha A^T A) stays regular.
// Second order: at h = 1e-3 it follows the projected rk8pd solution (an
// independent formulation) to O(h^2), and halving h divides the gap by ~4.
TEST(RedundantConstraints, AugmentedLagrangianRunsAndConvergesAtSecondOrder) {
  RunConfig ref_cfg = config("projection", "rk8pd");
  ref_cfg.step.rtol = ref_cfg.step.atol = 1e-12;
  const RunResult ref = run_case(problem(), ref_cfg, "");
  ASSERT_EQ(ref.status, "ok") << ref.reason;
  double gap[2];
  for (int k = 0; k < 2; ++k) {
    RunConfig cfg = config("ali3p", "own");
    cfg.step.step = k == 0 ? 2e-3 : 1e-3;
    const RunResult r = run_case(problem(), cfg, "");
    ASSERT_EQ(r.status, "ok") << r.reason;
    EXPECT_LT(r.max_residual, 1e-9);
    ASSERT_EQ(r.final_state.size(), 4u);
    gap[k] = 0;
    for (int i = 0; i < 4; ++i) gap[k] = std::max(gap[k], std::abs(r.final_state[i] - ref.final_state[i]));
  }
  EXPECT_LT(gap[1], 1e-3);
  EXPECT_NEAR(gap[0] / gap[1], 4.0, 0.6) << gap[0] << " " << gap[1];
}

// The penalty formulation runs on redundant rows too (M + p A^T A stays
// positive definite), but holds the constraints only to O(1/p): a hundred
// times the penalty, a hundred times smaller residual and gap to the
// projected rk8pd solution (an independent formulation).
TEST(RedundantConstraints, PenaltyRunsWithErrorsFallingAsOneOverThePenalty) {
  RunConfig ref_cfg = config("projection", "rk8pd");
  ref_cfg.step.rtol = ref_cfg.step.atol = 1e-12;
  const RunResult ref = run_case(problem(), ref_cfg, "");
  ASSERT_EQ(ref.status, "ok") << ref.reason;
  double residual[2], gap[2];
  for (int k = 0; k < 2; ++k) {
    RunConfig cfg = config("penalty", "rk8pd");
    cfg.step.rtol = cfg.step.atol = 1e-12;
    cfg.params = {{"alpha", k == 0 ? "1e4" : "1e6"}};
    const RunResult r = run_case(problem(), cfg, "");
    ASSERT_EQ(r.status, "ok") << r.reason;
    ASSERT_EQ(r.final_state.size(), 4u);
    residual[k] = r.max_residual;
    gap[k] = 0;
    for (int i = 0; i < 4; ++i) gap[k] = std::max(gap[k], std::abs(r.final_state[i] - ref.final_state[i]));
  }
  EXPECT_LT(residual[0], 1e-4);
  EXPECT_GT(residual[0], 1e-8) << "a penalty cannot hold the rows to the integrator's tolerance";
  EXPECT_NEAR(std::log10(residual[0] / residual[1]), 2.0, 0.3) << residual[0] << " " << residual[1];
  EXPECT_NEAR(std::log10(gap[0] / gap[1]), 2.0, 0.3) << gap[0] << " " << gap[1];
}

TEST(RedundantConstraints, FullRankMethodsRefuseWithAClearError) {
  for (const auto& [method, integrator] : std::vector<std::pair<std::string, std::string>>{
           {"baumgarte", "rk8pd"}, {"pesterev", "rk8pd"}, {"ida-index1", "ida"}, {"ida-ggl", "ida"},
           {"generalized-alpha", "own"}, {"hht", "own"}, {"generalized-alpha-i2", "own"}}) {
    try {
      run_case(problem(), config(method, integrator), "");
      ADD_FAILURE() << method << " ran on redundant constraints";
    } catch (const UsageError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("redundant") != std::string::npos || what.find("singular") != std::string::npos)
          << method << ": " << what;
    }
  }
}

}  // namespace
}  // namespace cstab

// Bricard's mechanism (IFToMM A04): twelve constraint rows of rank 11, one
// degree of freedom. The reference is the minimal-coordinate ODE in rod 1's
// angle (problems/bricard); it is checked against the closed-form energy and
// against the redundant DAE run by the methods that handle redundancy (an
// independent formulation). The methods that need full-rank rows do not
// apply, and say so naming the rank.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "linalg/dense.hpp"
#include "methods/mechanical.hpp"
#include "problems/bricard/bricard.hpp"
#include "problems/registry.hpp"

namespace cstab {
namespace {

constexpr int kCanonical = 24;

RunConfig config(const std::string& method, const std::string& integrator, double t_end) {
  RunConfig cfg;
  cfg.problem = "bricard";
  cfg.method = method;
  cfg.integrator = integrator;
  cfg.t_end = t_end;
  cfg.ref_time = t_end;
  cfg.write_series = false;
  if (integrator == "rk4" || integrator == "own") cfg.step.step = 1e-3;
  else cfg.step.rtol = cfg.step.atol = 1e-10;
  return cfg;
}

// Released at rest from P1..P4 = (1,0,0), (1,-1,0), (1,-1,1), (0,-1,1): the
// energy is the potential m g (y1 + y2 + y3 + y4) = -3 m g at every time.
TEST(BricardModel, ReferenceKeepsTheClosedFormEnergyAndEveryRow) {
  const Bricard problem;
  const BricardParameters& p = problem.parameters();
  const double energy = -3 * p.m * p.g;
  double c[kCanonical];
  double travelled = 0;
  for (double t : {0.0, 1.3, 2.7, 5.0, 7.5, 10.0}) {
    ASSERT_TRUE(problem.reference(t, c)) << t;
    EXPECT_NEAR(problem.energy(t, c), energy, 1e-9) << "t = " << t;
    Vec<double, 12> phi;
    bricard_detail::rows<double>(p.L, vmap<12>(c).eval(), phi);
    EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-12) << "t = " << t;
    travelled = std::max(travelled, std::abs(c[0] - 1.0));
  }
  // It moves, and far: rod 1 swings past the vertical (x1 from 1 to below 0).
  EXPECT_GT(travelled, 1.0);
}

// Twelve rows, rank 11: at the start and wherever the reference goes.
TEST(BricardModel, TwelveRowsOfRankElevenAlongTheMotion) {
  const Bricard problem;
  int rows = 0;
  EXPECT_EQ(initial_constraint_rank(problem.mechanical(), &rows), 11);
  EXPECT_EQ(rows, 12);
  MechanicalTerms<BricardMechanical> terms;
  double c[kCanonical];
  for (double t : {0.9, 3.1, 6.4}) {
    ASSERT_TRUE(problem.reference(t, c));
    terms.evaluate(problem.mechanical(), t, vmap<12>(c).eval(), vmap<12>(c + 12).eval(), false);
    EXPECT_EQ(linalg::rank_of(terms.A), 11) << "t = " << t;
    // The velocity lies in the null space of the rows.
    EXPECT_LT((terms.A * vmap<12>(c + 12)).lpNorm<Eigen::Infinity>(), 1e-10) << "t = " << t;
  }
}

// The redundant DAE through three methods with rank-revealing solves, tight:
// each agrees with the minimal-coordinate reference at t = 10, an independent
// formulation (post-stabilization 1.3e-11, braun-goldfarb 3.5e-12 and
// projection 5.9e-10 when this was written).
TEST(BricardReference, AgreesWithTheRedundantDaeThroughRankRevealingMethods) {
  const Problem& problem = find_problem("bricard");
  for (const auto& [method, params] : std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::string>>>>{
           {"post-stabilization", {}}, {"projection", {}}, {"braun-goldfarb", {{"dt", "1e-2"}}}}) {
    RunConfig cfg = config(method, "rk8pd", 10);
    cfg.params = params;
    const RunResult r = run_case(problem, cfg, "");
    ASSERT_EQ(r.status, "ok") << method << ": " << r.reason;
    EXPECT_LT(r.ref_error, 1e-8) << method;
    EXPECT_LT(r.max_residual, 1e-10) << method;
    EXPECT_LT(r.max_energy_drift, 1e-7) << method;
  }
}

// ali3p runs the redundant rows (its iteration matrix stays regular) at
// second order: halving h divides its error against the reference by ~4.
TEST(BricardReference, AugmentedLagrangianRunsTheRedundantRowsAtSecondOrder) {
  const Problem& problem = find_problem("bricard");
  double error[2];
  for (int k = 0; k < 2; ++k) {
    RunConfig cfg = config("ali3p", "own", 2);
    cfg.step.step = k == 0 ? 2e-3 : 1e-3;
    const RunResult r = run_case(problem, cfg, "");
    ASSERT_EQ(r.status, "ok") << r.reason;
    EXPECT_LT(r.max_residual, 1e-9);
    error[k] = r.ref_error;
  }
  EXPECT_LT(error[1], 1e-4);
  EXPECT_NEAR(error[0] / error[1], 4.0, 0.6) << error[0] << " " << error[1];
}

// An ordering: the unstabilized index-1 ODE drifts off the rows, and every
// rank-revealing stabilization holds them orders of magnitude closer.
TEST(BricardReference, NoneDriftsAndTheStabilizedMethodsDoNot) {
  const Problem& problem = find_problem("bricard");
  const RunResult none = run_case(problem, config("none", "rk8pd", 10), "");
  ASSERT_EQ(none.status, "ok") << none.reason;
  EXPECT_GT(none.max_residual, 1e-7);
  const RunResult projected = run_case(problem, config("projection", "rk8pd", 10), "");
  ASSERT_EQ(projected.status, "ok") << projected.reason;
  EXPECT_LT(projected.max_residual, 1e-3 * none.max_residual);
  EXPECT_LT(projected.ref_error, 1e-3 * none.ref_error);
}

// Every method that needs full-rank rows does not apply, and names the rank.
TEST(BricardRedundancy, FullRankMethodsDoNotApplyAndNameTheRank) {
  const Problem& problem = find_problem("bricard");
  for (const char* method : {"baumgarte", "pesterev", "rattle", "generalized-alpha", "hht", "generalized-alpha-i2",
                             "symmetric-projection", "ida-index1", "ida-ggl"}) {
    const std::string why = problem.why_not(method);
    EXPECT_NE(why.find("redundant"), std::string::npos) << method << ": " << why;
    EXPECT_NE(why.find("rank 11 of 12"), std::string::npos) << method << ": " << why;
    EXPECT_THROW(problem.make(method, "", Params{}), UsageError) << method;
  }
  for (const char* method : {"none", "projection", "post-stabilization", "braun-goldfarb", "penalty", "ali3p",
                             "minimal"})
    EXPECT_EQ(problem.why_not(method), "") << method;
}

}  // namespace
}  // namespace cstab

// cstab tune (harness/tune.hpp, cli/tune_command.cpp): the known answer of
// pesterev + RK4, bad input, and an unreachable target recorded as such.
//
// The known answer. Pesterev's feedback makes the constraint obey
// (d/dt + lambda)^2 Phi = 0 exactly, so from a perturbed start (--perturb)
// the residual of a fixed-step RK4 run decays, to first order, as the RK4
// amplification R(h K) of that linear system: with z = h lambda, its
// eigenvalue is R(-z), R(w) = 1 + w + w^2/2 + w^3/6 + w^4/24, and the
// residual after N steps is about Phi0 R(-z)^(N-1) (R(-z) + N z R'(-z)).
// For a step h the fastest damping per step is at the minimum of R on the
// real axis, R'(-z0) = 0: z0 = 1.5961, R(-z0) = 0.2704 (inside RK4's
// stability interval z < 2.785); there the Jordan term vanishes too. So the
// cheapest setting that damps the residual to a target by t_end (fewest
// steps) is h lambda = z0, up to a shift of about 0.25 / N from the Jordan
// term (2-3 % here). The pendulum hangs at rest (angle = 0), so the motion
// itself adds almost nothing to the residual (about 1e-10 over 0.1 s, below
// the target).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "harness/stability.hpp"
#include "harness/tune.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"

namespace fs = std::filesystem;
using namespace cstab;
using cstab::testing::contains;
using cstab::testing::quote;
using cstab::testing::Scratch;
using cstab::testing::slurp;

namespace {

// z0 > 0 with R'(-z0) = 0, R' (w) = 1 + w + w^2/2 + w^3/6: Newton from 1.5.
double rk4_fastest_damping() {
  double z = 1.5;
  for (int i = 0; i < 50; ++i) {
    const double w = -z;
    const double d1 = 1 + w + w * w / 2 + w * w * w / 6;  // R'(w)
    const double d2 = 1 + w + w * w / 2;                  // R''(w)
    z += d1 / d2;                                          // dw = -d1/d2, z = -w
  }
  return z;
}

double rk4_r(double w) { return 1 + w + w * w / 2 + w * w * w / 6 + w * w * w * w / 24; }

TuneConfig pendulum_config() {
  TuneConfig c;
  c.base.problem = "pendulum";
  c.base.problem_params = {{"angle", "0"}};
  c.base.method = "pesterev";
  c.base.integrator = "rk4";
  c.base.t_end = 0.1;
  c.base.perturb = 1e-3;
  c.measure = "final";
  c.target = 1e-8;
  c.cost = "rhs";  // equal steps cost the same: the gain alone decides
  c.repeats = 1;
  for (int n = 5; n <= 20; ++n) c.levels.push_back(0.1 / n);
  for (int i = 0; i <= 60; ++i) c.gains.push_back(50 * std::pow(10.0, i / 60.0));  // 50 .. 500, 3.9 % apart
  return c;
}

std::string usage_error(const TuneConfig& c) {
  try {
    check_tune(find_problem(c.base.problem), c);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(TuneKnownAnswer, ClosedFormOfRk4) {
  const double z0 = rk4_fastest_damping();
  EXPECT_NEAR(z0, 1.5961, 1e-4);
  EXPECT_NEAR(rk4_r(-z0), 0.2704, 1e-4);
  EXPECT_LT(z0, real_stability_boundary("rk4"));
}

TEST(TuneKnownAnswer, PesterevRk4FindsTheFastestDampingGain) {
  const TuneConfig cfg = pendulum_config();
  const TuneResult res = tune(find_problem("pendulum"), cfg);
  ASSERT_TRUE(res.reachable);
  const double z0 = rk4_fastest_damping();
  const double z = res.best.gain * res.best.level;
  EXPECT_NEAR(z / z0, 1.0, 0.10) << "best lambda = " << res.best.gain << ", h = " << res.best.level;
  // The step the linear theory predicts: the fewest steps N with
  // Phi0 R(-z0)^N <= target, give or take one for the Jordan term.
  const double phi0 = 2 * 1.0 * 1e-3 * std::sin(2.0);  // |2 y dy| at (0, -L), y moved by delta sin(2)
  const double n_theory = std::log(phi0 / cfg.target) / -std::log(rk4_r(-z0));
  const double n_best = cfg.base.t_end / res.best.level;
  EXPECT_NEAR(n_best, n_theory, 1.5) << "N = " << n_best << ", theory " << n_theory;
  // Sharper, with the Jordan term: at N steps the linear residual
  // Phi0 R^(N-1) (R(-z) + N z R'(-z)) vanishes at z_c just above z0; the
  // grid point the search finds lies within a few per cent of it.
  double lo = z0, hi = z0 + 0.5;
  const auto g = [&](double zz) {
    const double w = -zz;
    return rk4_r(w) + n_best * zz * (1 + w + w * w / 2 + w * w * w / 6);
  };
  for (int i = 0; i < 100; ++i) (g(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  const double z_c = 0.5 * (lo + hi);
  EXPECT_NEAR(z / z_c, 1.0, 0.04) << "z_c = " << z_c;
  std::printf("Jordan-corrected optimum at N = %g: z_c = %.4f (found %+.1f %%)\n", n_best, z_c, 100 * (z / z_c - 1));
  // Every reaching gain at the best step lies near z0 / h too.
  for (const auto& r : res.runs)
    if (r.reached && r.level == res.best.level) {
      EXPECT_NEAR(r.gain * r.level / z0, 1.0, 0.10) << r.gain;
    }
  EXPECT_GE(res.flat_count, 1);
  EXPECT_LE(res.flat_min, res.best.gain);
  EXPECT_GE(res.flat_max, res.best.gain);
  // The walk and the pruning kept the search well inside the box.
  EXPECT_LT(res.runs.size(), res.gains.size() * res.levels.size());
  EXPECT_EQ(res.case_runs, long(res.runs.size()));  // repeats = 1
  std::printf("best lambda = %g at h = %g (N = %g): lambda h = %.4f, z0 = %.4f (%+.1f %%); %zu runs, %.3g s\n",
              res.best.gain, res.best.level, n_best, z, z0, 100 * (z / z0 - 1), res.runs.size(), res.seconds);
}

TEST(TuneSearch, WalksEachGainCoarseToFineAndStopsAtItsFirstReach) {
  TuneConfig cfg = pendulum_config();
  cfg.prune_ratio = 0;  // walk every level
  cfg.gains = {100, 160, 230};
  const TuneResult res = tune(find_problem("pendulum"), cfg);
  for (double g : res.gains) {
    double previous = INFINITY;
    int reached = 0;
    for (const auto& r : res.runs) {
      if (r.gain != g) continue;
      EXPECT_LT(r.level, previous);  // coarse to fine
      EXPECT_EQ(reached, 0) << "ran on after reaching";
      previous = r.level;
      reached += r.reached;
    }
  }
  // lambda = 100 damps too slowly (h lambda <= 0.5) to reach within 20 steps.
  ASSERT_EQ(res.per_gain.size(), 2u);
  EXPECT_EQ(res.per_gain[0].gain, 160);
  EXPECT_EQ(res.per_gain[1].gain, 230);
  EXPECT_EQ(res.best.gain, 160);
  EXPECT_LT(res.runs.size(), 3 * res.levels.size());  // 100 walks every level; 160 and 230 stop early
}

TEST(TuneSearch, UnreachableTargetIsRecorded) {
  TuneConfig cfg = pendulum_config();
  cfg.target = 1e-30;
  cfg.gains = {100, 160};
  cfg.levels = {0.02, 0.01};
  const TuneResult res = tune(find_problem("pendulum"), cfg);
  EXPECT_FALSE(res.reachable);
  EXPECT_EQ(res.runs.size(), 4u);
  EXPECT_TRUE(res.per_gain.empty());
}

TEST(TuneSearch, DivergedRunsNeverReach) {
  TuneConfig cfg = pendulum_config();
  cfg.target = 1e300;  // any finished run reaches
  cfg.gains = {1000};  // h lambda = 20 at h = 0.02: unstable
  cfg.levels = {0.02, 0.001};
  const TuneResult res = tune(find_problem("pendulum"), cfg);
  ASSERT_EQ(res.runs.size(), 2u);
  EXPECT_NE(res.runs[0].status, "ok");
  EXPECT_FALSE(res.runs[0].reached);
  EXPECT_TRUE(res.runs[1].reached);
}

TEST(TuneSearch, DefaultGridsAreLogSpacedAndBounded) {
  const ParamSpec lambda{"lambda", 1500, Bound::kPositive, "", ParamRole::kRate};
  const auto g = default_tune_gains(lambda);
  ASSERT_EQ(g.size(), 13u);
  EXPECT_DOUBLE_EQ(g.front(), 47.4);  // 1500 x 10^-1.5, 3 digits
  EXPECT_DOUBLE_EQ(g.back(), 47400);
  EXPECT_DOUBLE_EQ(g[6], 1500);
  for (size_t i = 1; i < g.size(); ++i) EXPECT_NEAR(g[i] / g[i - 1], std::pow(10, 0.25), 0.01);
  const ParamSpec ranged = ranged_param("x", 0.5, 0.1, 1, "");
  for (double v : default_tune_gains(ranged)) {
    EXPECT_GE(v, 0.1);
    EXPECT_LE(v, 1);
  }
  EXPECT_EQ(default_tune_levels(true).size(), 13u);
  EXPECT_DOUBLE_EQ(default_tune_levels(true).front(), 0.1);
  EXPECT_NEAR(default_tune_levels(true).back(), 1e-4, 1e-18);
  EXPECT_NEAR(default_tune_levels(false).back(), 1e-11, 1e-25);
}

TEST(TuneBadInput, UsageErrorsNameTheProblem) {
  TuneConfig c = pendulum_config();
  c.base.method = "none";
  EXPECT_TRUE(contains(usage_error(c), "method 'none' declares no gain")) << usage_error(c);
  c = pendulum_config();
  c.base.method = "no-such-method";
  EXPECT_TRUE(contains(usage_error(c), "no-such-method")) << usage_error(c);
  c = pendulum_config();
  c.base.integrator = "no-such-integrator";
  EXPECT_TRUE(contains(usage_error(c), "no-such-integrator")) << usage_error(c);
  for (double bad : {0.0, -1.0, double(NAN), double(INFINITY)}) {
    c = pendulum_config();
    c.target = bad;
    EXPECT_TRUE(contains(usage_error(c), "--target")) << usage_error(c);
  }
  c = pendulum_config();
  c.gains = {10, -1};
  EXPECT_TRUE(contains(usage_error(c), "--gains")) << usage_error(c);
  c = pendulum_config();
  c.levels = {0.1, 0};
  EXPECT_TRUE(contains(usage_error(c), "--steps")) << usage_error(c);
  c = pendulum_config();
  c.measure = "speed";
  EXPECT_TRUE(contains(usage_error(c), "--measure speed")) << usage_error(c);
  c = pendulum_config();
  c.measure = "ref";  // the pendulum's reference is at t = 10 > t_end
  EXPECT_TRUE(contains(usage_error(c), "--measure ref")) << usage_error(c);
  c = pendulum_config();
  c.base.params = {{"lambda", "10"}};
  EXPECT_TRUE(contains(usage_error(c), "tuned gain")) << usage_error(c);
  c = pendulum_config();
  c.max_runs = 10;
  EXPECT_TRUE(contains(usage_error(c), "--max-runs")) << usage_error(c);
  EXPECT_THROW(find_problem("no-such-problem"), UsageError);
}

// The command: bad input exits 2 with one line and writes nothing; an
// unreachable target exits 0 with best.csv saying so.
TEST(TuneCli, BadInputExits2AndWritesNothing) {
  Scratch s;
  const fs::path out = s.dir() / "out";
  const std::string base = "tune --problem pendulum --problem-param angle=0 --integrator rk4 --t-end 0.1 "
                           "--perturb 1e-3 --measure final --out " + quote(out.string());
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--method none --target 1e-8", "method 'none' declares no gain"},
      {"--method pesterev --target 0", "--target"},
      {"--method pesterev --target nan", "--target"},
      {"--method pesterev --target 1e-8 --gains 1,,2", "--gains"},
      {"--method pesterev --target 1e-8 --steps 0.1,x", "--steps"},
      {"--method pesterev --target 1e-8 --tols 1e-6", "--tols"},
      {"--method frob --target 1e-8", "frob"},
      {"--method pesterev --target 1e-8 --problem-param angle=x", "angle"},
  };
  for (const auto& [args, message] : cases) {
    const auto o = cstab::testing::cstab_cmd(base + " " + args);
    EXPECT_EQ(o.code, 2) << args << ": " << o.out;
    EXPECT_TRUE(contains(o.out, "cstab tune: error: ")) << o.out;
    EXPECT_TRUE(contains(o.out, message)) << args << ": " << o.out;
    EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 1) << o.out;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
  const auto unknown = cstab::testing::cstab_cmd(
      "tune --problem frob --method pesterev --integrator rk4 --target 1 --out " + quote(out.string()));
  EXPECT_EQ(unknown.code, 2) << unknown.out;
  EXPECT_TRUE(contains(unknown.out, "frob")) << unknown.out;
  const auto integ = cstab::testing::cstab_cmd(
      "tune --problem pendulum --method pesterev --integrator frob --target 1 --out " + quote(out.string()));
  EXPECT_EQ(integ.code, 2) << integ.out;
  EXPECT_TRUE(contains(integ.out, "frob")) << integ.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(TuneCli, WritesTheSearchAndTheBestAndRecordsUnreachable) {
  Scratch s;
  const std::string base = "tune --problem pendulum --problem-param angle=0 --method pesterev --integrator rk4 "
                           "--t-end 0.1 --perturb 1e-3 --measure final --gains 100,160,230 --steps 0.02,0.01 "
                           "--no-plot --out ";
  const fs::path ok = s.dir() / "ok";
  const auto o = cstab::testing::cstab_cmd(base + quote(ok.string()) + " --target 1e-8");
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "best: lambda = 160, step = 0.01")) << o.out;
  EXPECT_TRUE(contains(o.out, "runs")) << o.out;
  EXPECT_TRUE(contains(o.out, "within 20 %")) << o.out;
  const std::string best = slurp(ok / "best.csv");
  EXPECT_TRUE(contains(best, ",ok,lambda,160,0.01")) << best;
  const std::string grid = slurp(ok / "tune.csv");
  EXPECT_TRUE(contains(grid, "gain,step,measure,value,target,reached,status,wall_median,repeats,rhs_evals")) << grid;
  EXPECT_EQ(std::count(grid.begin(), grid.end(), '\n'), 1 + 6) << grid;  // 3 gains x 2 steps, none reached at 0.02

  const fs::path no = s.dir() / "no";
  const auto u = cstab::testing::cstab_cmd(base + quote(no.string()) + " --target 1e-30");
  EXPECT_EQ(u.code, 0) << u.out;
  EXPECT_TRUE(contains(u.out, "unreachable")) << u.out;
  EXPECT_TRUE(contains(slurp(no / "best.csv"), ",unreachable,")) << slurp(no / "best.csv");
  for (const auto& e : fs::directory_iterator(no))  // no temporaries left
    EXPECT_TRUE(e.path().filename() == "best.csv" || e.path().filename() == "tune.csv") << e.path();
}

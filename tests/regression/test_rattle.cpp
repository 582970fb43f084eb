// rattle (methods/rattle.hpp) against what the theory says of it (Hairer,
// Lubich & Wanner, Geometric Numerical Integration, VII.1.4): second order
// in positions and velocities; symplectic for conservative forces, so on the
// IFToMM A01 pendulum (constant M, one holonomic row, an energy law) the
// energy error stays bounded over 1e4 periods, where RK4 + projection at the
// same step drifts linearly; and where it does not apply (non-holonomic
// rows, a mass matrix that changes with q) it says why and writes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "problems/registry.hpp"
#include "tests/support/order_util.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

using testing::contains;
using testing::cstab_cmd;
using testing::Outcome;
using testing::quote;
using testing::Scratch;

RunResult run(const std::string& problem, const std::string& method, const std::string& integrator, double h,
              double t_end, double ref_time, int observe_every = 1) {
  RunConfig cfg;
  cfg.problem = problem;
  cfg.method = method;
  cfg.integrator = integrator;
  cfg.step.step = h;
  cfg.t_end = t_end;
  cfg.ref_time = ref_time;
  cfg.write_series = false;
  cfg.observe_every = observe_every;
  if (method == "rattle") cfg.params = {{"tol", "1e-14"}};
  return run_case(find_problem(problem), cfg, "");
}

TEST(RattleOrder, SecondOrderOnTheSliderCrank) {
  testing::expect_second_order("slider-crank", "rattle", {{"tol", "1e-14"}}, 10, 4e-3);
}
TEST(RattleOrder, SecondOrderOnThePendulum) {
  testing::expect_second_order("pendulum", "rattle", {{"tol", "1e-14"}}, 10, 2e-2);
}

// The pendulum released horizontally: period 4 sqrt(L / g) K(sin 45 deg)
// (L = 1, g = 9.81; K(1/sqrt 2) = 1.8540746773013719). Over 1e4 periods at
// h = 1e-2 (about 240 steps a period) rattle's energy error oscillates
// without growing (fitted exponent of the running max |dE| ~ t^p near 0),
// while RK4 + projection at the same step grows linearly (p ~ 1), from a
// comparable error early on.
TEST(RattleEnergy, BoundedOverTenThousandPeriodsWhereProjectionDrifts) {
  const double period = 4 * std::sqrt(1.0 / 9.81) * 1.8540746773013719;
  const double t_end = 1e4 * period;
  const RunResult rattle = run("pendulum", "rattle", "own", 1e-2, t_end, 0, 10);
  const RunResult projection = run("pendulum", "projection", "rk4", 1e-2, t_end, 0, 10);
  ASSERT_EQ(rattle.status, "ok") << rattle.reason;
  ASSERT_EQ(projection.status, "ok") << projection.reason;
  std::cout << "[ energy   ] pendulum, 1e4 periods (t = " << t_end << "), h = 1e-2: rattle max |dE| "
            << rattle.max_energy_drift << ", exponent " << rattle.energy_drift_exponent
            << "; rk4 + projection max |dE| " << projection.max_energy_drift << ", exponent "
            << projection.energy_drift_exponent << "\n";
  EXPECT_LT(std::abs(rattle.energy_drift_exponent), 0.1);
  EXPECT_GT(projection.energy_drift_exponent, 0.8);
  // Bounded: the largest error of the whole run is that of the first period
  // or so, O(h^2) (1 - cos of the energy's oscillation), not a growing one.
  const RunResult first = run("pendulum", "rattle", "own", 1e-2, 10 * period, 0, 10);
  ASSERT_EQ(first.status, "ok") << first.reason;
  EXPECT_LE(rattle.max_energy_drift, 1.01 * first.max_energy_drift);
  // The constraint holds to the position solve's tolerance all the way.
  EXPECT_LT(rattle.max_residual, 1e-11);
}

// Where rattle does not apply, `cstab run` says why, exits 2 and writes no
// folder; the same for its bad parameters.
TEST(RattleRefusals, SaysWhyExitsTwoAndWritesNothing) {
  Scratch s("cstab_rattle");
  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {"--problem andrews --method rattle",
       "--method rattle: the mass matrix changes with the configuration or time"},
      {"--problem wheel --method rattle", "--method rattle: 1 non-holonomic constraint row: rattle is for holonomic"},
      {"--problem ball --method rattle", "2 non-holonomic constraint rows"},
      {"--problem pendulum --method rattle --param tol=0", "tol"},
      {"--problem pendulum --method rattle --param tol=-1e-9", "tol"},
      {"--problem pendulum --method rattle --param iterations=0", "iterations"},
      {"--problem pendulum --method rattle --param iterations=2.5", "iterations"},
  };
  int k = 0;
  for (const Case& c : cases) {
    const std::filesystem::path out = s.dir() / ("out" + std::to_string(k++));
    const Outcome o = cstab_cmd("run " + c.args + " --integrator own --step 1e-3 --t-end 1 --out " +
                                quote(out.string()) + " 2>&1");
    EXPECT_EQ(o.code, 2) << c.args << "\n" << o.out;
    EXPECT_TRUE(contains(o.out, c.expected)) << c.args << "\n" << o.out;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
}

}  // namespace
}  // namespace cstab

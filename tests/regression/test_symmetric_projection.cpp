// symmetric-projection (methods/symmetric_projection.hpp) against what the
// theory says of it (Hairer, BIT 40 (2000); Hairer, Lubich & Wanner,
// Geometric Numerical Integration, V.4.1): second order, like its base
// method (the implicit midpoint rule); symmetric, so on a reversible
// problem (the IFToMM A01 pendulum: one holonomic row, an energy law) the
// energy error stays bounded over many periods, where the plain projection
// around the same midpoint step (symmetric = 0) drifts; and where it does
// not apply it says why and writes nothing.
#include <gtest/gtest.h>

#include <cmath>
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

RunResult run(const std::string& problem, double h, double t_end, bool symmetric, int observe_every = 1) {
  RunConfig cfg;
  cfg.problem = problem;
  cfg.method = "symmetric-projection";
  cfg.integrator = "own";
  cfg.step.step = h;
  cfg.t_end = t_end;
  cfg.ref_time = 0;
  cfg.write_series = false;
  cfg.observe_every = observe_every;
  cfg.params = {{"tol", "1e-14"}, {"symmetric", symmetric ? "1" : "0"}};
  return run_case(find_problem(problem), cfg, "");
}

// Second order, like the midpoint rule it is built on.
TEST(SymmetricProjectionOrder, SecondOrderOnThePendulum) {
  testing::expect_second_order("pendulum", "symmetric-projection", {{"tol", "1e-14"}}, 10, 2e-2);
}
TEST(SymmetricProjectionOrder, SecondOrderOnTheSliderCrank) {
  testing::expect_second_order("slider-crank", "symmetric-projection", {{"tol", "1e-14"}}, 10, 4e-3);
}

// The pendulum released horizontally (period 4 sqrt(L / g) K(sin 45 deg),
// L = 1, g = 9.81, K(1/sqrt 2) = 1.8540746773013719), 1e4 periods at
// h = 2e-2 (about 120 steps a period): the symmetric projection's energy
// error oscillates without growing (fitted exponent of the running max
// |dE| ~ t^p near 0) while the plain projection around the same midpoint
// step grows (p near 1). GNI V.4 (the symmetric projection keeps the
// symmetric base method's long-time behaviour; the standard one does not).
TEST(SymmetricProjectionEnergy, BoundedWherePlainProjectionAroundTheSameStepDrifts) {
  const double period = 4 * std::sqrt(1.0 / 9.81) * 1.8540746773013719;
  const double t_end = 1e4 * period, h = 2e-2;
  const RunResult sym = run("pendulum", h, t_end, true, 10);
  const RunResult plain = run("pendulum", h, t_end, false, 10);
  ASSERT_EQ(sym.status, "ok") << sym.reason;
  ASSERT_EQ(plain.status, "ok") << plain.reason;
  std::cout << "[ energy   ] pendulum, 1e4 periods (t = " << t_end << "), h = " << h
            << ": symmetric projection max |dE| " << sym.max_energy_drift << ", exponent "
            << sym.energy_drift_exponent << "; plain projection max |dE| " << plain.max_energy_drift << ", exponent "
            << plain.energy_drift_exponent << "\n";
  EXPECT_LT(std::abs(sym.energy_drift_exponent), 0.1);
  EXPECT_GT(plain.energy_drift_exponent, 0.8);
  // Bounded: the largest error of the whole run is that of the first ten periods.
  const RunResult first = run("pendulum", h, 10 * period, true, 10);
  ASSERT_EQ(first.status, "ok") << first.reason;
  EXPECT_LE(sym.max_energy_drift, 1.01 * first.max_energy_drift);
  // Both stay on the manifold to the projection's tolerance.
  EXPECT_LT(sym.max_residual, 1e-11);
  EXPECT_LT(plain.max_residual, 1e-11);
}

// Where it does not apply, `cstab run` says why, exits 2 and writes no
// folder; the same for its bad parameters.
TEST(SymmetricProjectionRefusals, SaysWhyExitsTwoAndWritesNothing) {
  Scratch s("cstab_symproj");
  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {"--problem wheel", "non-holonomic constraint row"},
      {"--problem ball", "non-holonomic constraint rows"},
      {"--problem pendulum --param symmetric=2", "symmetric"},
      {"--problem pendulum --param symmetric=0.5", "symmetric"},
      {"--problem pendulum --param tol=0", "tol"},
      {"--problem pendulum --param iterations=0", "iterations"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const std::string out = (s.dir() / "out").string();
    const Outcome o = cstab_cmd("run " + c.args + " --method symmetric-projection --integrator own --step 1e-3 " +
                                "--t-end 0.01 --out " + quote(out) + " 2>&1");
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_TRUE(contains(o.out, c.expected)) << o.out;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

}  // namespace
}  // namespace cstab

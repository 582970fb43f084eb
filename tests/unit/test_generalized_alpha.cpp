// The generalized-alpha family (methods/generalized_alpha.hpp) against what
// the papers prove: second order in positions and velocities (Arnold & Bruls
// 2007) on the suite's problems; its Newton statistics; and the CLI's answer
// to bad parameters. The linear analysis (spectral radius, conditioning) is in
// test_generalized_alpha_linear.cpp (apart, each unit compiles in under 1 GB).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "methods/generalized_alpha.hpp"
#include "problems/registry.hpp"
#include "tests/support/order_util.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

using testing::log_slope;
using testing::tight_reference;

// ---- observed order against the references ----

struct Errors {
  double position = 0, velocity = 0;
};

// Max error over the first `n_pos` canonical coordinates (positions) and the
// rest (velocities) at the reference time, against `ref` (NaN: unscored).
Errors split_errors(const RunResult& r, const std::vector<double>& ref, size_t n_pos) {
  Errors e;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (std::isnan(ref[i])) continue;
    const double d = std::abs(r.state_at_ref[i] - ref[i]);
    (i < n_pos ? e.position : e.velocity) = std::max(i < n_pos ? e.position : e.velocity, d);
  }
  return e;
}

RunResult run_own(const std::string& problem, const std::string& method, double h, double t_end) {
  RunConfig cfg;
  cfg.problem = problem;
  cfg.method = method;
  cfg.integrator = "own";
  cfg.step.step = h;
  cfg.t_end = t_end;
  cfg.ref_time = t_end;
  cfg.write_series = false;
  if (method == "ali3p")
    cfg.params = {{"tol", "1e-13"}, {"iterations", "200"}};
  else
    cfg.params = {{"newton_tol", "1e-13"}, {"newton_iterations", "30"}};
  return run_case(find_problem(problem), cfg, "");
}

struct OrderCase {
  std::string problem;
  double t_end, h_max;  // h from h_max down a decade
};

void expect_second_order(const OrderCase& oc, const std::string& method) {
  const Problem& p = find_problem(oc.problem);
  const size_t n_pos = p.info().coordinates.size() / 2;
  // Positions against the problem's reference; velocities against a tight run
  // where the reference does not publish them.
  const std::vector<double> tight = tight_reference(oc.problem, oc.t_end);
  std::vector<double> hs, pos, vel;
  for (double f : {1.0, 0.5, 0.25, 0.1}) {
    const double h = oc.h_max * f;
    const RunResult r = run_own(oc.problem, method, h, oc.t_end);
    ASSERT_EQ(r.status, "ok") << method << " h = " << h << ": " << r.reason;
    const Errors published = split_errors(r, r.ref_state, n_pos);
    const Errors against_tight = split_errors(r, tight, n_pos);
    hs.push_back(h);
    pos.push_back(published.position);
    vel.push_back(against_tight.velocity);
    std::cout << "[ order    ] " << oc.problem << " " << method << " h = " << h << ": position error "
              << published.position << ", velocity error " << against_tight.velocity << "\n";
  }
  const double position_order = log_slope(hs, pos), velocity_order = log_slope(hs, vel);
  std::cout << "[ order    ] " << oc.problem << " " << method << ": observed order positions " << position_order
            << ", velocities " << velocity_order << "\n";
  EXPECT_GE(position_order, 1.8) << oc.problem << " " << method;
  EXPECT_LE(position_order, 2.2) << oc.problem << " " << method;
  EXPECT_GE(velocity_order, 1.8) << oc.problem << " " << method;
  EXPECT_LE(velocity_order, 2.2) << oc.problem << " " << method;
}

class SecondOrder : public ::testing::TestWithParam<std::string> {};

TEST_P(SecondOrder, SliderCrank) { expect_second_order({"slider-crank", 10, 4e-3}, GetParam()); }
TEST_P(SecondOrder, Andrews) { expect_second_order({"andrews", 0.03, 4e-5}, GetParam()); }

INSTANTIATE_TEST_SUITE_P(GeneralizedAlpha, SecondOrder,
                         ::testing::Values("generalized-alpha", "hht", "generalized-alpha-i2", "ali3p"),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string s = i.param;
                           for (char& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

// ---- statistics and starting values ----

TEST(GeneralizedAlphaRun, ReportsNewtonStatisticsAndKeepsConstraints) {
  for (const std::string method : {"generalized-alpha", "hht", "generalized-alpha-i2"}) {
    const RunResult r = run_own("slider-crank", method, 1e-3, 1.0);
    ASSERT_EQ(r.status, "ok") << r.reason;
    std::map<std::string, std::string> extra(r.extra.begin(), r.extra.end());
    ASSERT_TRUE(extra.count("newton_iters")) << method;
    ASSERT_TRUE(extra.count("newton_conv_fails")) << method;
    // At least one iteration per step (1000 steps), and none failed.
    EXPECT_GE(std::stol(extra["newton_iters"]), 1000) << method;
    EXPECT_EQ(extra["newton_conv_fails"], "0") << method;
    EXPECT_EQ(r.steps, 1000);
    // Position constraints to the Newton tolerance; index 2 also the velocity rows.
    EXPECT_LT(r.max_residual, 1e-10) << method;
  }
}

// ---- bad input through the CLI ----

struct CliOutcome {
  int code;
  std::string err;
};

CliOutcome run_cli(const std::vector<std::string>& args, const std::filesystem::path& scratch) {
  std::string cmd = testing::quote(CSTAB_BINARY);
  for (const auto& a : args) {
    cmd += ' ';
    cmd += testing::quote(a);
  }
  const auto err = scratch / "stderr.txt";
  cmd += " >/dev/null 2>";
  cmd += testing::quote(err.string());
  const int status = std::system(cmd.c_str());
  return {testing::exit_code(status), testing::slurp(err)};
}

struct BadCase {
  std::string method, integrator, param, named;
};

TEST(GeneralizedAlphaCli, BadParametersExitTwoWithOneLineAndNoOutput) {
  const std::vector<BadCase> cases = {
      {"generalized-alpha", "own", "rho_inf=1.5", "rho_inf"},
      {"generalized-alpha-i2", "own", "rho_inf=-0.1", "rho_inf"},
      {"hht", "own", "alpha=-0.5", "alpha"},
      {"hht", "own", "alpha=0.1", "alpha"},
      {"generalized-alpha", "own", "newton_iterations=0", "newton_iterations"},
      {"generalized-alpha", "own", "newton_iterations=2.5", "newton_iterations"},
      {"generalized-alpha", "own", "newton_tol=0", "newton_tol"},
      {"ali3p", "own", "alpha=0", "alpha"},
      {"ali3p", "own", "alpha=-1e9", "alpha"},
      {"ali3p", "own", "iterations=0", "iterations"},
      {"ali3p", "own", "tol=nan", "tol"},
      {"penalty", "rk4", "alpha=0", "alpha"},
      {"penalty", "rk4", "omega=-10", "omega"},
      {"penalty", "rk4", "xi=nan", "xi"},
      {"penalty", "own", "", "--integrator"},
      {"generalized-alpha", "rk4", "rho_inf=0.5", "--integrator"},  // wrong pairing
      {"baumgarte", "own", "", "--integrator"},
  };
  for (const auto& c : cases) {
    testing::Scratch s("cstab_genalpha_cli");
    const auto out = s.dir() / "out";
    std::vector<std::string> args = {"run", "--problem", "slider-crank", "--method", c.method, "--integrator",
                                     c.integrator, "--step", "1e-3", "--t-end", "0.1", "--out", out.string()};
    if (!c.param.empty()) {
      args.push_back("--param");
      args.push_back(c.param);
    }
    const CliOutcome o = run_cli(args, s.dir());
    EXPECT_EQ(o.code, 2) << c.method << " " << c.param << ": " << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    EXPECT_NE(o.err.find(c.named), std::string::npos) << o.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.method << " " << c.param;
  }
  // The range is named in the message.
  testing::Scratch s("cstab_genalpha_cli");
  const CliOutcome o = run_cli({"run", "--problem", "slider-crank", "--method", "generalized-alpha", "--integrator",
                                "own", "--step", "1e-3", "--t-end", "0.1", "--param", "rho_inf=1.5", "--out",
                                (s.dir() / "out").string()},
                               s.dir());
  EXPECT_NE(o.err.find("[0, 1]"), std::string::npos) << o.err;
}

}  // namespace
}  // namespace cstab

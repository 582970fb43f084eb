// cstab score: a trajectory computed elsewhere gets the metrics of cstab run.
// Checked against cstab run itself (a run's own series, every step written,
// scored again gives its summary), against closed forms (a pendulum
// trajectory on a circle of the wrong radius, whose residual and energy are
// known), and for bad input (exit 2, file:line:column, nothing written).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "harness/run.hpp"
#include "harness/score.hpp"
#include "io/csv.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

namespace fs = std::filesystem;
using testing::Scratch;
using testing::contains;
using testing::cstab_cmd;
using testing::quote;

std::map<std::string, std::string> summary_of(const fs::path& file) {
  const CsvTable t = read_csv(file.string());
  std::map<std::string, std::string> row;
  for (size_t i = 0; i < t.header.size(); ++i) row[t.header[i]] = t.rows.at(0).at(i);
  return row;
}

// What describes the producer rather than the trajectory, and timing: the
// only columns in which a score may differ from the run that wrote the
// trajectory. max_condition is the condition of the method's reaction
// matrix, which a trajectory does not carry; perturb is the run's setting
// (the perturbed start itself is in the trajectory: initial_residual).
const std::set<std::string> kProducerColumns = {
    "method", "params", "integrator", "step", "rtol", "atol", "rhs_evals", "rejected_steps", "wall_seconds",
    "observe_seconds", "max_condition", "perturb", "rows", "differenced", "ref_interpolation", "initial_state_deviation"};

struct Case {
  std::string problem, method, formulation, integrator;
  double step, t_end, perturb;
};

// Runs `c` writing every step to the series, scores that series, and
// compares every column of the two summaries but the producer's.
void expect_score_reproduces_run(const Case& c) {
  SCOPED_TRACE(c.problem + " / " + c.method);
  Scratch s;
  RunConfig cfg;
  cfg.problem = c.problem;
  cfg.method = c.method;
  cfg.formulation = c.formulation;
  cfg.integrator = c.integrator;
  cfg.step.step = c.step;
  cfg.t_end = c.t_end;
  cfg.perturb = c.perturb;
  cfg.sample_every = 1e-300;  // every observed step is a series row
  const Problem& problem = find_problem(c.problem);
  const RunResult run = run_case(problem, cfg, (s.dir() / "run").string());
  ASSERT_EQ(run.status, "ok") << run.reason;
  // What the comparison covers: a fitted drift exponent where the horizon allows one.
  if (run.has_energy && c.t_end >= 4 * cfg.drift_fit_from) {
    EXPECT_FALSE(std::isnan(run.energy_drift_exponent));
  }
  if (c.perturb > 0) {
    EXPECT_GT(run.initial_residual, 1e-5);
  }

  ScoreConfig sc;
  sc.problem = c.problem;
  sc.sample_every = 1e-300;
  const RunResult scored =
      score_trajectory(problem, sc, (s.dir() / "run" / "series.csv").string(), (s.dir() / "score").string());
  const auto a = summary_of(s.dir() / "run" / "summary.csv");
  const auto b = summary_of(s.dir() / "score" / "summary.csv");
  size_t compared = 0;
  for (const auto& [column, value] : a) {
    if (kProducerColumns.count(column)) continue;
    ASSERT_TRUE(b.count(column)) << "the score has no column " << column;
    EXPECT_EQ(b.at(column), value) << column;
    ++compared;
  }
  for (const auto& [column, value] : b)
    EXPECT_TRUE(a.count(column) || kProducerColumns.count(column)) << "extra column " << column;
  EXPECT_GE(compared, 20u);
  // The series too, every row and column but the run's `cond` (its method's).
  const std::string scored_series = testing::slurp(s.dir() / "score" / "series.csv");
  const std::string header = scored_series.substr(0, scored_series.find('\n'));
  std::set<std::string> names;
  for (size_t at = 0, comma; at <= header.size(); at = comma + 1) {
    comma = std::min(header.find(',', at), header.size());
    names.insert(header.substr(at, comma - at));
  }
  EXPECT_EQ(scored_series, csv_select_columns(testing::slurp(s.dir() / "run" / "series.csv"), names));
  EXPECT_EQ(b.at("method"), "external");
  EXPECT_EQ(b.at("rhs_evals"), "");
  EXPECT_EQ(b.at("steps"), a.at("steps"));
  EXPECT_EQ(scored.extra.at(1).second, "none");  // differenced
}

TEST(Score, ReproducesTheSummaryOfTheRunThatWroteTheTrajectory) {
  // The pendulum over 60 s: energy drift and its growth exponent (fitted from t = 10).
  expect_score_reproduces_run({"pendulum", "baumgarte", "", "rk4", 1e-2, 60, 0});
  // The slider crank to its reference time: error and correct digits at t = 10.
  expect_score_reproduces_run({"slider-crank", "projection", "", "rk4", 1e-2, 10, 0});
  // The ball: first integrals besides energy.
  expect_score_reproduces_run({"ball", "pesterev", "", "rk4", 1e-3, 1, 0});
  // The wheel in its state-space form (the form whose state is the canonical one).
  expect_score_reproduces_run({"wheel", "pesterev", "state-space", "rk4", 1e-3, 1, 0});
  // A perturbed start: initial residual and recovery time.
  expect_score_reproduces_run({"car-axis", "baumgarte", "", "rk4", 1e-3, 1, 1e-3});
  // Runtime-size models (their state is the canonical one): n-four-bar
  // through its first singular position, fekete to its reference time.
  expect_score_reproduces_run({"n-four-bar", "post-stabilization", "", "rk4", 1e-2, 2, 0});
  expect_score_reproduces_run({"fekete", "projection", "", "rk4", 1e-2, 20, 0});
}

// theta(t) = 0.3 sin(2 t) on a circle of radius L + d: the residual
// x^2 + y^2 - L^2 is (L + d)^2 - L^2 on every row, and the energy is known.
struct Circle {
  double L = 1, d = 1e-3, m = 1, g = 9.81;
  double theta(double t) const { return 0.3 * std::sin(2 * t); }
  double theta_dot(double t) const { return 0.6 * std::cos(2 * t); }
  double energy(double t) const {
    const double r = L + d, w = theta_dot(t);
    return 0.5 * m * r * r * w * w - m * g * r * std::cos(theta(t));
  }
  // Rows every h over [0, t_end]; without the velocity columns if !velocities.
  std::string csv(double h, int rows, bool velocities) const {
    std::ostringstream out;
    out.precision(17);
    out << (velocities ? "t,x,y,xdot,ydot\n" : "t,y,x\n");
    for (int k = 0; k < rows; ++k) {
      const double t = k * h, r = L + d, th = theta(t), w = theta_dot(t);
      const double x = r * std::sin(th), y = -r * std::cos(th);
      if (velocities)
        out << t << "," << x << "," << y << "," << r * std::cos(th) * w << "," << r * std::sin(th) * w << "\n";
      else
        out << t << "," << y << "," << x << "\n";
    }
    return out.str();
  }
};

fs::path write(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

TEST(Score, ATrajectoryOffTheConstraintByAKnownAmountReportsThatAmount) {
  Scratch s;
  const Circle c;
  const fs::path file = write(s.dir() / "circle.csv", c.csv(1e-3, 2001, true));
  ScoreConfig sc;
  sc.problem = "pendulum";
  const RunResult r = score_trajectory(find_problem("pendulum"), sc, file.string(), "");
  ASSERT_EQ(r.status, "ok");
  const double expected = (c.L + c.d) * (c.L + c.d) - c.L * c.L;
  EXPECT_NEAR(r.max_residual, expected, 1e-14);
  EXPECT_NEAR(r.final_residual, expected, 1e-14);
  EXPECT_NEAR(r.initial_residual, expected, 1e-14);
  // The energy drift, max over the rows of |E(t) - E(0)| in closed form.
  double drift = 0;
  for (int k = 0; k <= 2000; ++k) drift = std::max(drift, std::abs(c.energy(k * 1e-3) - c.energy(0)));
  EXPECT_NEAR(r.max_energy_drift, drift, 1e-12 * (1 + drift));
  EXPECT_EQ(r.steps, 2000);
  EXPECT_TRUE(std::isnan(r.ref_error));  // t = 2 is before the pendulum's reference time (10)
}

TEST(Score, MissingVelocitiesAreDifferencedToSecondOrderAndSaidSo) {
  Scratch s;
  const Circle c;
  ScoreConfig sc;
  sc.problem = "pendulum";
  // Columns in another order than the problem's, velocities missing.
  double previous_error = 0;
  for (double h : {2e-3, 1e-3}) {
    const int rows = int(std::lround(2.0 / h)) + 1;
    const fs::path file = write(s.dir() / "positions.csv", c.csv(h, rows, false));
    const RunResult r = score_trajectory(find_problem("pendulum"), sc, file.string(), "");
    ASSERT_EQ(r.status, "ok");
    EXPECT_EQ(r.extra.at(1).first, "differenced");
    EXPECT_EQ(r.extra.at(1).second, "xdot;ydot");
    // The final state's velocity against the closed form (a one-sided end).
    const double t = 2.0, rr = c.L + c.d, th = c.theta(t), w = c.theta_dot(t);
    const double error = std::max(std::abs(r.final_state[2] - rr * std::cos(th) * w),
                                  std::abs(r.final_state[3] - rr * std::sin(th) * w));
    EXPECT_LT(error, 10 * h * h);
    if (previous_error > 0) {
      EXPECT_NEAR(previous_error / error, 4.0, 0.5);  // second order
    }
    previous_error = error;
  }
}

TEST(Score, AReferenceTimeBetweenRowsIsInterpolatedThroughFourRows) {
  Scratch s;
  // The slider crank's own run on a grid that skips t = 10 (step 0.03), then
  // the same run with t = 10 as an output: the interpolated error agrees.
  RunConfig cfg;
  cfg.problem = "slider-crank";
  cfg.method = "projection";
  cfg.integrator = "rk4";
  cfg.step.step = 1e-3;
  cfg.t_end = 10.02;
  cfg.sample_every = 0.03;
  cfg.ref_time = 0;  // the run's own error is not what is compared
  const Problem& problem = find_problem("slider-crank");
  run_case(problem, cfg, (s.dir() / "run").string());
  ScoreConfig sc;
  sc.problem = "slider-crank";
  sc.ref_time = 10;
  const RunResult scored = score_trajectory(problem, sc, (s.dir() / "run" / "series.csv").string(), "");
  EXPECT_EQ(scored.extra.at(2).second, "cubic");
  cfg.ref_time = 10;
  cfg.write_series = false;
  const RunResult direct = run_case(problem, cfg, "");
  ASSERT_FALSE(std::isnan(direct.ref_error));
  // A cubic through rows 0.03 apart: O(h^4) of a motion of unit scale.
  EXPECT_NEAR(scored.ref_error, direct.ref_error, 1e-4);
  for (size_t i = 0; i < direct.state_at_ref.size(); ++i)
    EXPECT_NEAR(scored.state_at_ref[i], direct.state_at_ref[i], 1e-4) << i;
}

// Bad input: exit 2, one message naming the file, line and column, and no
// output folder left behind.
void expect_refused(const std::string& problem, const std::string& text, const std::string& message,
                    const std::string& extra_args = "") {
  SCOPED_TRACE(message);
  Scratch s;
  const fs::path file = write(s.dir() / "traj.csv", text);
  const auto o = cstab_cmd("score --problem " + problem + " " + extra_args + " " + quote(file.string()) +
                           " --out " + quote((s.dir() / "out").string()));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, message)) << o.out;
  EXPECT_FALSE(fs::exists(s.dir() / "out"));
}

TEST(Score, BadInputIsRefusedWithFileLineAndColumnAndNothingWritten) {
  const std::string ok = "t,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0,0\n";
  expect_refused("pendulum", "t,x,y,xdot,ydot,zz\n0,1,0,0,0,0\n", "traj.csv:1:17: unknown column 'zz'");
  expect_refused("pendulum", "t,x,xdot,ydot\n0,1,0,0\n0.1,1,0,0\n", "traj.csv:1: missing column 'y'");
  expect_refused("pendulum", "t,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0,0\n0.1,1,0,0,0\n",
                 "traj.csv:4:1: t = 0.1 does not increase");
  expect_refused("pendulum", "t,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,nan,0,0\n", "traj.csv:3:7: 'nan' is not finite");
  expect_refused("pendulum", "t,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,abc,0,0\n", "traj.csv:3:7: 'abc' is not a number");
  expect_refused("pendulum", "t,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0\n", "traj.csv:3: 4 cells, the header has 5");
  expect_refused("pendulum", "t,x,y,xdot,ydot\n0,1,0,0,0\n", "1 rows; scoring needs at least 2");
  expect_refused("pendulum", "t,x,y,x,ydot\n0,1,0,0,0\n", "traj.csv:1:7: column 'x' appears twice");
  expect_refused("pendulum", "x,y,xdot,ydot\n1,0,0,0\n", "no column 't'");
  expect_refused("pendulum", "", "empty (no header line)");
  // A trajectory of another problem (the slider crank's columns).
  expect_refused("pendulum", "t,q,x,p,qdot,xdot,pdot\n0,0,0,0,0,0,0\n0.1,0,0,0,0,0,0\n",
                 "unknown column 'q': problem 'pendulum' has t,x,y,xdot,ydot");
  expect_refused("pendulum", ok, "--formulation minimal: problem 'pendulum' scores", "--formulation minimal");
  expect_refused("nosuch", ok, "nosuch");
  expect_refused("pendulum", ok, "--blowup: must be > 0", "--blowup -1");
  expect_refused("pendulum", "# wall_seconds = -3\n" + ok, "traj.csv:1: wall_seconds '-3' is not a number >= 0");
}

TEST(Score, AnExistingResultIsKeptWhenTheInputIsBad) {
  Scratch s;
  const fs::path out = s.dir() / "out";
  fs::create_directories(out);
  write(out / "summary.csv", "kept\n");
  const fs::path file = write(s.dir() / "traj.csv", "t,x,y,xdot,ydot\n0,1,0,0,0\n0,1,0,0,0\n");
  const auto o = cstab_cmd("score --problem pendulum " + quote(file.string()) + " --out " + quote(out.string()));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_EQ(testing::slurp(out / "summary.csv"), "kept\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator()), 1);
}

TEST(Score, TheWallTimeComesFromTheFileOrTheFlag) {
  Scratch s;
  const fs::path file = write(s.dir() / "traj.csv", "# made by another simulator\n# wall_seconds = 0.25\n"
                                                    "t,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0,0\n");
  const auto o = cstab_cmd("score --problem pendulum --label peer " + quote(file.string()) + " --out " +
                           quote((s.dir() / "a").string()));
  ASSERT_EQ(o.code, 0) << o.out;
  auto row = summary_of(s.dir() / "a" / "summary.csv");
  EXPECT_EQ(row.at("wall_seconds"), "0.25");
  EXPECT_EQ(row.at("method"), "peer");
  EXPECT_EQ(row.at("integrator"), "external");
  const auto o2 = cstab_cmd("score --problem pendulum --wall-seconds 2 --no-series " + quote(file.string()) +
                            " --out " + quote((s.dir() / "b").string()));
  ASSERT_EQ(o2.code, 0) << o2.out;
  EXPECT_EQ(summary_of(s.dir() / "b" / "summary.csv").at("wall_seconds"), "2");
  EXPECT_FALSE(fs::exists(s.dir() / "b" / "series.csv"));
  // The pendulum's initial state is (L sin 90deg, -L cos 90deg) at rest: this trajectory starts there.
  EXPECT_LT(std::stod(summary_of(s.dir() / "b" / "summary.csv").at("initial_state_deviation")), 1e-15);
}

}  // namespace
}  // namespace cstab

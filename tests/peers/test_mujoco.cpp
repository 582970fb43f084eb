// cstab-peer-mujoco (peers/mujoco/, docs/peers-mujoco.md): the MuJoCo
// models start from cstab's own initial state and energy, `cstab score`
// reads what the program writes, and the constraint residual orders with
// MuJoCo's accuracy knobs. The program's path comes from
// peers/mujoco/CMakeLists.txt (CSTAB_PEER_MUJOCO); where MuJoCo is not
// installed the program is not built and these tests skip.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "problems/n_four_bar/n_four_bar.hpp"
#include "problems/pendulum/pendulum.hpp"

namespace {

namespace fs = std::filesystem;

#ifdef CSTAB_PEER_MUJOCO
const char* kPeer = CSTAB_PEER_MUJOCO;
#define SKIP_WITHOUT_PEER() (void)0
#else
const char* kPeer = "";
#define SKIP_WITHOUT_PEER() GTEST_SKIP() << "cstab-peer-mujoco is not built (MuJoCo not found)"
#endif

struct Outcome {
  int code = -1;
  std::string out;  // stdout and stderr
};

Outcome run(const std::string& command) {
  Outcome o;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return o;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) o.out.append(buf, n);
  const int status = pclose(p);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) out.push_back(cell);
  return out;
}

class PeerMujoco : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("cstab-test-mujoco-" + std::to_string(::getpid()) + "-" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  // Runs the peer; returns the trajectory's path (asserting exit 0).
  fs::path simulate(const std::string& name, const std::string& args) {
    const fs::path out = dir / (name + ".csv");
    const auto o = run(std::string(kPeer) + " " + args + " --out " + out.string());
    EXPECT_EQ(o.code, 0) << o.out;
    return out;
  }

  // `cstab score` of a trajectory: the summary row, column -> text.
  std::map<std::string, std::string> score(const std::string& problem, const fs::path& csv,
                                           const std::string& extra = "") {
    const fs::path out = dir / (csv.stem().string() + "-scored");
    const auto o = run(std::string(CSTAB_BINARY) + " score --problem " + problem + " " + extra + " " +
                       csv.string() + " --out " + out.string());
    EXPECT_EQ(o.code, 0) << o.out;
    std::ifstream in(out / "summary.csv");
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    const auto h = split(header), r = split(row);
    std::map<std::string, std::string> m;
    for (size_t i = 0; i < h.size() && i < r.size(); ++i) m[h[i]] = r[i];
    return m;
  }

  static double number(const std::map<std::string, std::string>& m, const std::string& key) {
    const auto it = m.find(key);
    if (it == m.end() || it->second.empty()) return NAN;
    return std::stod(it->second);
  }

  // The first data row of a trajectory (after the # lines and the header).
  static std::vector<double> first_row(const fs::path& csv, std::string* first_line = nullptr) {
    std::ifstream in(csv);
    std::string line;
    bool header = false;
    while (std::getline(in, line)) {
      if (first_line && first_line->empty()) *first_line = line;
      if (line.empty() || line[0] == '#') continue;
      if (!header) {
        header = true;
        continue;
      }
      std::vector<double> v;
      for (const auto& c : split(line)) v.push_back(std::stod(c));
      return v;
    }
    return {};
  }
};

// n-four-bar (`cstab score` has no observer for its runtime-size model, so
// these compare with NFourBar's own initial state, energy, rows and
// reference). The trajectory: its header and rows, the values of each row.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

Table read_table(const fs::path& csv) {
  Table t;
  std::ifstream in(csv);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (t.header.empty()) {
      t.header = split(line);
      continue;
    }
    std::vector<double> v;
    for (const auto& c : split(line)) v.push_back(std::stod(c));
    t.rows.push_back(v);
  }
  return t;
}

double max_abs_difference(const double* a, const double* b, size_t n) {
  double d = 0;
  for (size_t i = 0; i < n; ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

// The largest |row| of the natural formulation's 2N + 1 bar constraints
// (|B_i - A_i|^2 - L^2, |B_(i+1) - B_i|^2 - L^2) at a canonical state.
double max_bar_residual(const cstab::NFourBar& problem, const double* canonical) {
  std::vector<double> phi(size_t(problem.scalable().rows()));
  problem.scalable().holonomic(canonical, phi.data());
  double r = 0;
  for (double x : phi) r = std::max(r, std::abs(x));
  return r;
}

TEST_F(PeerMujoco, NFourBarStartIsCstabsToRoundOff) {
  SKIP_WITHOUT_PEER();
  for (const int N : {1, 3, 40, 200}) {
    SCOPED_TRACE("N = " + std::to_string(N));
    cstab::NFourBarParameters p;
    p.N = N;
    const cstab::NFourBar problem(p);
    const size_t n = size_t(problem.canonical_size());
    // N = 40 is the default: no parameter.
    const std::string param = N == 40 ? "" : " --problem-param N=" + std::to_string(N);
    const Table t = read_table(simulate(
        "start", "--problem n-four-bar" + param + " --integrator rk4 --timestep 1e-3 --t-end 0.01 --every 0.01"));
    // The header is cstab's coordinates, in cstab's order.
    std::vector<std::string> expected = {"t"};
    for (const auto& c : problem.info().coordinates) expected.push_back(c);
    EXPECT_EQ(t.header, expected);
    ASSERT_EQ(t.rows.size(), 2u);
    ASSERT_EQ(t.rows[0].size(), n + 1);
    EXPECT_EQ(t.rows[0][0], 0.0);
    const double* row = t.rows[0].data() + 1;
    std::vector<double> start(n);
    problem.scalable().initial_state(start.data(), start.data() + n / 2);
    // B_i = (i L + L cos(pi/2), L sin(pi/2)): cos(pi/2) = 6.1e-17.
    const double deviation = max_abs_difference(row, start.data(), n);
    EXPECT_LE(deviation, 4e-16);
    EXPECT_LE(max_bar_residual(problem, row), 4e-16);
    const double e0 = problem.energy(0, start.data()), e = problem.energy(0, row);
    EXPECT_NEAR(e, e0, 4e-16 * std::abs(e0)) << "E0 = " << e0;
    std::printf("n-four-bar N = %d: initial state deviation %.3g, residual %.3g, energy %.17g vs %.17g (diff %.3g)\n",
                N, deviation, max_bar_residual(problem, row), e, e0, e - e0);
  }
}

// The largest |error| against cstab's reference (every canonical
// coordinate, velocities included) of an N = 40 run to t = 0.5.
double n_four_bar_error(const Table& t, double t_end) {
  const cstab::NFourBar problem;
  std::vector<double> ref(size_t(problem.canonical_size()));
  if (t.rows.empty() || t.rows.back()[0] != t_end || !problem.reference(t_end, ref.data())) return NAN;
  return max_abs_difference(t.rows.back().data() + 1, ref.data(), ref.size());
}

// A short N = 40 run (RK4, to t = 0.5) against cstab's reference: the error
// is the soft connects' (docs/peers-mujoco.md), so it falls as solref's time
// constant does. Measured: 3.61e-3, 9.77e-5, 6.46e-6 (error, every
// canonical coordinate at t = 0.5); |E - E0| 2.39e-3, 8.25e-5, 5.82e-6 J of
// E0 = 620.34 J. The bounds are those with a factor ~1.5-3 of margin. With
// every bar's central inertia 5 % too large the runs measured 6.8e-3,
// 6.2e-3, 6.1e-3 and |E - E0| 0.51 J: the mass properties are checked.
TEST_F(PeerMujoco, NFourBarShortRunConvergesToTheReference) {
  SKIP_WITHOUT_PEER();
  struct Case {
    std::string timestep, solref;
    double max_error, max_energy_drift;
  };
  const cstab::NFourBar problem;
  double previous = INFINITY;
  for (const Case& c : {Case{"1e-3", "0.02,1", 6e-3, 5e-3}, Case{"1e-3", "0.002,1", 2e-4, 2e-4},
                        Case{"1e-4", "0.0005,1", 2e-5, 1.5e-5}}) {
    SCOPED_TRACE("timestep " + c.timestep + ", solref " + c.solref);
    const Table t = read_table(simulate("short", "--problem n-four-bar --integrator rk4 --timestep " + c.timestep +
                                                     " --t-end 0.5 --every 0.01 --solref " + c.solref));
    ASSERT_EQ(t.rows.size(), 51u);
    const double error = n_four_bar_error(t, 0.5);
    const double drift =
        std::abs(problem.energy(0, t.rows.back().data() + 1) - problem.energy(0, t.rows[0].data() + 1));
    std::printf("n-four-bar N = 40, rk4, h = %s, solref %s: error at t = 0.5 %.3g, |E - E0| %.3g\n", c.timestep.c_str(),
                c.solref.c_str(), error, drift);
    EXPECT_LE(error, c.max_error);
    EXPECT_LE(drift, c.max_energy_drift);
    EXPECT_LT(error, previous / 10);
    previous = error;
  }
}

TEST_F(PeerMujoco, InitialStateIsCstabsToRoundOff) {
  SKIP_WITHOUT_PEER();
  struct Case {
    std::string problem, params, score_params;
  };
  for (const Case& c : {Case{"pendulum", "", ""},
                        Case{"pendulum", "--problem-param length=1.7,angle=30",
                             "--problem-param length=1.7 --problem-param angle=30"},
                        Case{"slider-crank", "", ""}}) {
    SCOPED_TRACE(c.problem + " " + c.params);
    std::string first_line;
    const auto csv = simulate("start", "--problem " + c.problem + " " + c.params +
                                           " --integrator rk4 --timestep 1e-3 --t-end 0.1 --every 0.01");
    const auto row = first_row(csv, &first_line);
    EXPECT_EQ(first_line.rfind("# wall_seconds = ", 0), 0u) << first_line;
    ASSERT_FALSE(row.empty());
    EXPECT_EQ(row[0], 0.0);
    const auto s = score(c.problem, csv, c.score_params);
    EXPECT_EQ(s.at("status"), "ok");
    // The largest difference between the first row and the problem's own
    // initial state, and the constraint residual there: round-off.
    EXPECT_LE(number(s, "initial_state_deviation"), 4e-16);
    EXPECT_LE(std::abs(number(s, "initial_residual")), 4e-16);
    EXPECT_GT(number(s, "wall_seconds"), 0.0);
  }
}

TEST_F(PeerMujoco, PendulumInitialEnergyIsCstabs) {
  SKIP_WITHOUT_PEER();
  for (const auto& [L, angle] : std::vector<std::pair<double, double>>{{1.0, 90.0}, {1.7, 30.0}}) {
    cstab::PendulumParameters p;
    p.L = L;
    p.angle = angle;
    const cstab::Pendulum pendulum(p);
    char args[200];
    std::snprintf(args, sizeof args,
                  "--problem pendulum --problem-param length=%.17g,angle=%.17g --integrator euler "
                  "--timestep 1e-3 --t-end 0.01 --every 0.01",
                  L, angle);
    const auto row = first_row(simulate("energy", args));
    ASSERT_EQ(row.size(), 5u);
    // E = m |v|^2 / 2 + m g y of the first row against -m g L cos theta0.
    EXPECT_NEAR(pendulum.energy(0, row.data() + 1), pendulum.closed_form_energy(), 1e-14) << L << " " << angle;
  }
}

// MuJoCo's constraints are soft: the residual is set by solref's time
// constant (a stiffer one, a smaller residual), at any timestep.
TEST_F(PeerMujoco, ResidualShrinksWithTheSolrefTimeConstant) {
  SKIP_WITHOUT_PEER();
  for (const std::string problem : {"pendulum", "slider-crank"}) {
    for (const std::string integrator : {"euler", "rk4", "implicit"}) {
      SCOPED_TRACE(problem + " " + integrator);
      double previous = INFINITY;
      for (const std::string solref : {"0.02,1", "0.01,1", "0.005,1"}) {
        const auto csv = simulate("solref", "--problem " + problem + " --integrator " + integrator +
                                                " --timestep 1e-3 --t-end 2 --every 0.01 --solref " + solref);
        const double r = number(score(problem, csv), "max_residual");
        EXPECT_LT(r, previous) << "solref " << solref;
        EXPECT_GT(r, 0.0);
        previous = r;
      }
    }
  }
}

// At a solref time constant below 2 H MuJoCo uses 2 H (its "refsafe"), so
// there the residual shrinks with the timestep; at the default solref it
// does not (docs/peers-mujoco.md).
TEST_F(PeerMujoco, ResidualShrinksWithTheTimestepAtAStiffSolref) {
  SKIP_WITHOUT_PEER();
  for (const std::string problem : {"pendulum", "slider-crank"}) {
    for (const std::string integrator : {"euler", "rk4", "implicit"}) {
      SCOPED_TRACE(problem + " " + integrator);
      double previous = INFINITY;
      for (const std::string h : {"1e-3", "5e-4", "2.5e-4"}) {
        const auto csv = simulate("h", "--problem " + problem + " --integrator " + integrator + " --timestep " + h +
                                           " --t-end 2 --every 0.01 --solref 0.0005,1");
        const double r = number(score(problem, csv), "max_residual");
        EXPECT_LT(r, previous) << "timestep " << h;
        previous = r;
      }
    }
  }
}

TEST_F(PeerMujoco, BadInputExits2WithOneLine) {
  SKIP_WITHOUT_PEER();
  const std::string ok = " --integrator rk4 --timestep 1e-3 --t-end 1 --every 0.01 --out " + (dir / "b.csv").string();
  for (const std::string& args : std::vector<std::string>{
           "--problem wheel" + ok, "--problem pendulum --integrator rk5 --timestep 1e-3 --t-end 1 --every 0.01 --out x",
           "--problem pendulum --problem-param mass=2" + ok, "--problem slider-crank --problem-param length=2" + ok,
           "--problem pendulum --problem-param length=-1" + ok, "--problem n-four-bar --problem-param N=0" + ok,
           "--problem n-four-bar --problem-param N=1001" + ok, "--problem n-four-bar --problem-param N=2.5" + ok,
           "--problem n-four-bar --problem-param N=many" + ok, "--problem n-four-bar --problem-param M=3" + ok,
           "--problem pendulum --integrator rk4 --timestep 0 --t-end 1 --every 0.01 --out x",
           "--problem pendulum --integrator rk4 --timestep 3e-3 --t-end 1 --every 0.01 --out x",
           "--problem pendulum --integrator rk4 --timestep 1e-3 --t-end 1 --every 0.01",
           "--problem pendulum --solref 0.02" + ok, "--problem pendulum --solref 0.02,nan" + ok,
           "--problem pendulum --solimp 2,0.95,0.001" + ok, "--problem pendulum --bogus 1" + ok,
           "--problem pendulum --integrator rk4 --timestep 1e-3 --t-end 1 --every 0.01 --out /nonexistent/dir/x.csv"}) {
    SCOPED_TRACE(args);
    const auto o = run(std::string(kPeer) + " " + args);
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 1) << o.out;
    EXPECT_EQ(o.out.rfind("cstab-peer-mujoco: ", 0), 0u) << o.out;
  }
  EXPECT_FALSE(fs::exists(dir / "b.csv"));
}

// An explicit stiffness far beyond what the timestep resolves: MuJoCo warns
// of a bad qacc; the rows before it are written, the warning printed, exit 1.
TEST_F(PeerMujoco, InstabilityWritesWhatWasSimulatedAndExits1) {
  SKIP_WITHOUT_PEER();
  const fs::path out = dir / "unstable.csv";
  const auto o = run(std::string(kPeer) +
                     " --problem pendulum --integrator euler --timestep 0.01 --solref -1e12,-1 --t-end 10 "
                     "--every 0.01 --out " + out.string());
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("QACC"), std::string::npos) << o.out;
  const auto row = first_row(out);
  ASSERT_EQ(row.size(), 5u);
  EXPECT_EQ(row[0], 0.0);
}

}  // namespace

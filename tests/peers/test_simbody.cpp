// cstab-peer-simbody (peers/simbody/) against cstab's own problems: the state
// it writes at t = 0 and Simbody's initial energy equal cstab's to round-off,
// its runs score within a bound set by the constraint tolerance, and bad
// input or a Simbody failure ends as documented. For the car axis, which has
// no energy law, Simbody's accelerations at the first and the last row equal
// those of cstab's equations of motion at the same state. For the N four-bar
// (which `cstab score` cannot read yet: no formulation of a runtime-size
// problem is its observer) the rows are compared with cstab's reference,
// rows and energy directly. CSTAB_PEER_SIMBODY is defined
// by peers/simbody/CMakeLists.txt when the adapter is built; without Simbody
// every test here skips.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "problems/andrews/andrews.hpp"
#include "problems/bricard/bricard.hpp"
#include "problems/car_axis/car_axis.hpp"
#include "problems/n_four_bar/n_four_bar.hpp"
#include "problems/pendulum/pendulum.hpp"
#include "problems/slider_crank/slider_crank.hpp"

namespace {

namespace fs = std::filesystem;

#ifdef CSTAB_PEER_SIMBODY
#define REQUIRE_PEER() (void)0
const std::string kPeer = CSTAB_PEER_SIMBODY;
#else
#define REQUIRE_PEER() GTEST_SKIP() << "cstab-peer-simbody not built (Simbody not found)"
const std::string kPeer;
#endif

struct Outcome {
  int code = -1;
  std::string out;
};

Outcome run(const std::string& command) {
  Outcome o;
  std::FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return o;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) o.out.append(buf, n);
  const int status = ::pclose(p);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

fs::path scratch_dir() { return fs::temp_directory_path() / ("cstab-test-simbody-" + std::to_string(::getpid())); }

fs::path scratch(const std::string& name) {
  fs::create_directories(scratch_dir());
  return scratch_dir() / name;
}

struct RemoveScratch : ::testing::Environment {
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(scratch_dir(), ec);
  }
};
const auto* const kRemoveScratch = ::testing::AddGlobalTestEnvironment(new RemoveScratch);

// The '#' lines (key -> value) and the rows (column -> values) of a file.
struct Trajectory {
  std::map<std::string, std::string> meta;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  double at(size_t row, const std::string& column) const {
    const auto it = std::find(columns.begin(), columns.end(), column);
    EXPECT_NE(it, columns.end()) << column;
    return rows.at(row).at(static_cast<size_t>(it - columns.begin()));
  }
};

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) cells.push_back(cell);
  return cells;
}

Trajectory read(const fs::path& path) {
  Trajectory tr;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '#') {
      const size_t eq = line.find('=');
      if (eq == std::string::npos) continue;
      std::string key = line.substr(1, eq - 1), value = line.substr(eq + 1);
      key.erase(0, key.find_first_not_of(' '));
      key.erase(key.find_last_not_of(' ') + 1);
      value.erase(0, value.find_first_not_of(' '));
      tr.meta[key] = value;
    } else if (tr.columns.empty()) {
      tr.columns = split(line);
    } else {
      std::vector<double> row;
      for (const auto& c : split(line)) row.push_back(std::stod(c));
      tr.rows.push_back(row);
    }
  }
  return tr;
}

// One row of a summary.csv written by `cstab score`: column -> text.
std::map<std::string, std::string> summary(const fs::path& dir) {
  std::ifstream in(dir / "summary.csv");
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  const auto h = split(header), r = split(row + ",");
  std::map<std::string, std::string> out;
  for (size_t i = 0; i < h.size(); ++i) out[h[i]] = i < r.size() ? r[i] : "";
  return out;
}

Outcome peer(const std::string& args) { return run("'" + kPeer + "' " + args); }
Outcome score(const std::string& problem, const fs::path& csv, const fs::path& out) {
  return run(std::string("'") + CSTAB_BINARY + "' score --problem " + problem + " '" + csv.string() + "' --out '" +
             out.string() + "'");
}

constexpr double kEps = 2.220446049250313e-16;

// The state at t = 0 equals cstab's initial canonical state to round-off,
// and Simbody's energy of it (kinetic plus gravity) equals cstab's energy().
void check_pendulum_start(const std::string& params, double L, double angle) {
  const fs::path csv = scratch("pendulum-start.csv");
  const Outcome o = peer("--problem pendulum " + params + " --integrator rkmerson --t-end 0.1 --every 0.1 --out '" +
                         csv.string() + "'");
  ASSERT_EQ(o.code, 0) << o.out;
  const Trajectory tr = read(csv);
  ASSERT_EQ(tr.columns, (std::vector<std::string>{"t", "x", "y", "xdot", "ydot"}));
  ASSERT_GE(tr.rows.size(), 2u);

  cstab::PendulumParameters p;
  p.L = L;
  p.angle = angle;
  const cstab::Pendulum problem(p);
  cstab::Vec<double, 2> q, v;
  problem.mechanical().initial_state(q, v);
  double c[4];
  problem.mechanical().to_canonical(0.0, q, v, c);
  EXPECT_EQ(tr.rows[0][0], 0.0);
  const char* names[] = {"x", "y", "xdot", "ydot"};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(tr.at(0, names[i]), c[i], 4 * kEps * L) << names[i];

  const double e_cstab = problem.energy(0.0, c);
  const double e_simbody = std::stod(tr.meta.at("simbody_initial_energy"));
  EXPECT_NEAR(e_simbody, e_cstab, 8 * kEps * p.m * p.g * L) << "cstab " << e_cstab << ", Simbody " << e_simbody;
  EXPECT_NEAR(e_cstab, problem.closed_form_energy(), 8 * kEps * p.m * p.g * L);
}

TEST(SimbodyPeer, PendulumStartsAtCstabsStateAndEnergy) {
  REQUIRE_PEER();
  check_pendulum_start("", 1.0, 90.0);
  check_pendulum_start("--problem-param length=2.5,angle=60", 2.5, 60.0);
  check_pendulum_start("--problem-param angle=-120 --problem-param length=0.3", 0.3, -120.0);
}

TEST(SimbodyPeer, SliderCrankStartsAtCstabsStateAndEnergy) {
  REQUIRE_PEER();
  const fs::path csv = scratch("slider-crank-start.csv");
  const Outcome o = peer("--problem slider-crank --integrator rkmerson --t-end 0.1 --every 0.1 --out '" +
                         csv.string() + "'");
  ASSERT_EQ(o.code, 0) << o.out;
  const Trajectory tr = read(csv);
  ASSERT_EQ(tr.columns, (std::vector<std::string>{"t", "q", "x", "p", "qdot", "xdot", "pdot"}));

  const cstab::SliderCrankParameters p;
  const cstab::SliderCrankMechanical model(p);
  cstab::Vec<double, 3> q, v;
  model.initial_state(q, v);
  double c[6];
  model.to_canonical(0.0, q, v, c);
  const char* names[] = {"q", "x", "p", "qdot", "xdot", "pdot"};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(tr.at(0, names[i]), c[i], 4 * kEps) << names[i];

  // cstab has no energy law for the slider crank (damped and forced), so its
  // energy is restated from cstab's parameters: kinetic energy of
  // M = diag(J1, m2, J2) plus the spring's k/2 (l - l0)^2, l as in
  // SliderCrankMechanical::forces (crank midpoint to rod midpoint). Simbody
  // counts the same two; its ConstantForce has no potential, so F's
  // -F (x + cos p) is left out of both.
  const double a = p.a, c1 = std::cos(c[0]), c2 = std::cos(c[2]), s1 = std::sin(c[0]), s2 = std::sin(c[2]);
  const double x = c[1];
  const double l = std::sqrt(x * x - x * (c2 + a * c1) + (1 + a * a) / 4 + a * (c2 * c1 + s2 * s1) / 2);
  const double e_cstab = 0.5 * (p.J1 * c[3] * c[3] + p.m2 * c[4] * c[4] + p.J2 * c[5] * c[5]) +
                         0.5 * p.k * (l - p.l0) * (l - p.l0);
  const double e_simbody = std::stod(tr.meta.at("simbody_initial_energy"));
  EXPECT_GT(e_cstab, 0.1);  // the spring starts stretched from l0 = 1 to l = 0.43
  EXPECT_NEAR(e_simbody, e_cstab, 16 * kEps) << "cstab " << e_cstab << ", Simbody " << e_simbody;
}

// Bricard's mechanism, with either closure of the loop at P5 (the revolute's
// five rows, one of them redundant, or four): the columns are cstab's
// coordinates, the first row is cstab's initial state (P1..P4 at rest) to
// round-off, and Simbody's energy of it (five rods' kinetic energy plus
// gravity's potential, zero at y = 0) is cstab's energy().
TEST(SimbodyPeer, BricardStartsAtCstabsStateAndEnergy) {
  REQUIRE_PEER();
  const cstab::Bricard problem;
  const cstab::BricardParameters& p = problem.parameters();
  std::vector<std::string> columns = {"t"};
  for (const auto& name : problem.info().coordinates) columns.push_back(name);
  ASSERT_EQ(columns.size(), 25u);
  cstab::Vec<double, 12> q, v;
  problem.mechanical().initial_state(q, v);
  double c[24];
  problem.mechanical().to_canonical(0.0, q, v, c);
  const double e_cstab = problem.energy(0.0, c);
  for (const std::string closure : {"redundant", "independent"}) {
    const fs::path csv = scratch("bricard-start-" + closure + ".csv");
    const Outcome o = peer("--problem bricard --closure " + closure +
                           " --integrator rkmerson --t-end 0.1 --every 0.1 --out '" + csv.string() + "'");
    ASSERT_EQ(o.code, 0) << o.out;
    const Trajectory tr = read(csv);
    ASSERT_EQ(tr.columns, columns);
    ASSERT_GE(tr.rows.size(), 2u);
    EXPECT_EQ(tr.meta.at("simbody_closure"), closure);
    EXPECT_EQ(tr.rows[0][0], 0.0);
    for (int i = 0; i < 24; ++i)
      EXPECT_NEAR(tr.rows[0][i + 1], c[i], 4 * kEps * p.L) << closure << " " << columns[i + 1];
    // Five rods' potentials m g y_centre summed (cstab counts each joint's
    // height once for the two rods it ends): a few roundings of m g L each.
    const double e_simbody = std::stod(tr.meta.at("simbody_initial_energy"));
    EXPECT_NEAR(e_simbody, e_cstab, 5 * 8 * kEps * p.m * p.g * p.L)
        << closure << ": cstab " << e_cstab << ", Simbody " << e_simbody;
  }
}

// `cstab score` of a short run: the deviation of the first row from cstab's
// own initial state is round-off, every residual stays within a small
// multiple of the constraint tolerance (Simbody projects when its weighted
// norm of the errors passes the tolerance; the pendulum's x^2 + y^2 - L^2 is
// 2L times the rod's length error), a tighter tolerance gives a smaller
// residual, and the tight Merson run follows cstab's reference (the
// dynamics, not only the start, match).
TEST(SimbodyPeer, ScoredResidualsFollowTheConstraintTolerance) {
  REQUIRE_PEER();
  for (const std::string problem : {"pendulum", "slider-crank"}) {
    for (const std::string integrator : {"rkmerson", "verlet"}) {
      std::map<double, double> residual;  // accuracy -> max residual
      std::map<double, double> ref_error;
      for (const double accuracy : {1e-3, 1e-6}) {
        const double tolerance = 0.1 * accuracy;
        const std::string tag = problem + "-" + integrator + "-" + std::to_string(accuracy);
        const fs::path csv = scratch(tag + ".csv"), dir = scratch(tag);
        char acc[32];
        std::snprintf(acc, sizeof acc, "%.17g", accuracy);
        const Outcome o = peer("--problem " + problem + " --integrator " + integrator + " --accuracy " + acc +
                               " --t-end 10 --every 0.1 --out '" + csv.string() + "'");
        ASSERT_EQ(o.code, 0) << o.out;
        const Outcome s = score(problem, csv, dir);
        ASSERT_EQ(s.code, 0) << s.out;
        const auto row = summary(dir);
        EXPECT_EQ(row.at("status"), "ok") << tag;
        EXPECT_LE(std::stod(row.at("initial_state_deviation")), 4 * kEps) << tag;
        const double r = std::stod(row.at("max_residual"));
        EXPECT_LE(r, 10 * tolerance) << tag;
        residual[accuracy] = r;
        ref_error[accuracy] = std::stod(row.at("ref_error"));
      }
      EXPECT_LT(residual[1e-6], residual[1e-3]) << problem << " " << integrator;
      // Verlet's second-order global error at 1e-6 is still 4e-3 on the
      // pendulum (measured), so only the fourth-order Merson checks the
      // dynamics: a model whose masses or forces differ from cstab's would be
      // off by far more than 1e-3 after 10 s.
      if (integrator == "rkmerson") {
        EXPECT_LT(ref_error[1e-6], 1e-3) << problem;
      }
    }
  }
}

// Bricard's mechanism over the benchmark's 10 s, scored against cstab's own
// reference and energy: the first row is cstab's initial state, the residual
// of cstab's twelve rows stays within a small multiple of Simbody's
// constraint tolerance at its default accuracy and at 1e-6, and at 1e-6 the
// run ends near cstab's reference with its energy kept (the masses,
// inertias and gravity agree in motion, not only at the start). At the
// default accuracy the redundant closure's run may leave the reference (the
// projection issue docs/peers-simbody.md describes), so only its residual is
// checked there; the independent closure is held to the reference at 1e-2.
TEST(SimbodyPeer, BricardScoredRunFollowsCstabsReference) {
  REQUIRE_PEER();
  auto scored = [](const std::string& closure, double accuracy) {
    char acc[32];
    std::snprintf(acc, sizeof acc, "%.17g", accuracy);
    const std::string tag = "bricard-" + closure + "-" + acc;
    const fs::path csv = scratch(tag + ".csv"), dir = scratch(tag);
    const Outcome o = peer("--problem bricard --closure " + closure + " --integrator rkmerson --accuracy " + acc +
                           " --t-end 10 --every 0.1 --out '" + csv.string() + "'");
    EXPECT_EQ(o.code, 0) << o.out;
    const Outcome s = score("bricard", csv, dir);
    EXPECT_EQ(s.code, 0) << s.out;
    const auto row = summary(dir);
    EXPECT_EQ(row.at("status"), "ok") << tag;
    EXPECT_LE(std::stod(row.at("initial_state_deviation")), 4 * kEps) << tag;
    // cstab's rows are squared lengths and products of unit-length vectors:
    // a closure error e at P5 shows as about 2 L e in rod5's row.
    EXPECT_LE(std::stod(row.at("max_residual")), 10 * 0.1 * accuracy) << tag;
    return row;
  };
  const auto loose = scored("redundant", 1e-3);
  const auto tight = scored("redundant", 1e-6);
  ASSERT_FALSE(HasFailure());
  EXPECT_LT(std::stod(tight.at("max_residual")), std::stod(loose.at("max_residual")));
  EXPECT_LT(std::stod(tight.at("ref_error")), 1e-3);
  EXPECT_LT(std::stod(tight.at("max_energy_drift")), 1e-3);
  const auto independent = scored("independent", 1e-3);
  EXPECT_LT(std::stod(independent.at("ref_error")), 1e-2);
  EXPECT_LT(std::stod(independent.at("max_energy_drift")), 1e-2);
}

// Andrews' squeezing mechanism: the columns are cstab's coordinates, the
// first row is the Test Set's initial state (Simbody's initialization moves
// it by round-off, its q's projected onto the closure), and Simbody's energy
// of it (the spring's; its MobilityConstantForce has no potential) is
// cstab's energy plus mom beta (cstab counts the torque's potential -mom beta).
TEST(SimbodyPeer, AndrewsStartsAtCstabsStateAndEnergy) {
  REQUIRE_PEER();
  const cstab::Andrews problem;
  const cstab::AndrewsParameters& p = problem.mechanical().parameters();
  const fs::path csv = scratch("andrews-start.csv");
  const Outcome o =
      peer("--problem andrews --integrator rkmerson --t-end 0.001 --every 0.001 --out '" + csv.string() + "'");
  ASSERT_EQ(o.code, 0) << o.out;
  const Trajectory tr = read(csv);
  std::vector<std::string> columns = {"t"};
  for (const auto& name : problem.info().coordinates) columns.push_back(name);
  ASSERT_EQ(tr.columns, columns);
  ASSERT_GE(tr.rows.size(), 2u);
  cstab::Vec<double, 7> q, v;
  problem.mechanical().initial_state(q, v);
  double c[14];
  problem.mechanical().to_canonical(0.0, q, v, c);
  EXPECT_EQ(tr.rows[0][0], 0.0);
  // The angles are radians of order 1.
  for (int i = 0; i < 14; ++i) EXPECT_NEAR(tr.rows[0][i + 1], c[i], 4 * kEps) << columns[i + 1];
  const double e_cstab = problem.energy(0.0, c) + p.mom * c[0];
  const double e_simbody = std::stod(tr.meta.at("simbody_initial_energy"));
  EXPECT_GT(e_cstab, 1.0);  // the spring starts stretched
  EXPECT_NEAR(e_simbody, e_cstab, 16 * kEps * e_cstab) << "cstab " << e_cstab << ", Simbody " << e_simbody;
}

// Andrews over the Test Set's 0.03 s, scored against its published angles
// and cstab's energy law: the residual of g1..g6 (metres) stays within 10x
// the constraint tolerance, shrinks from accuracy 1e-3 to 1e-6, and at 1e-6
// the run ends within 1e-3 of the reference with cstab's energy (torque
// included) kept to 1e-3 of the spring's initial energy.
// rkmerson on `problem` at each accuracy, each trajectory scored into
// rows[accuracy], with what every scored run must show: status ok, the start
// at cstab's state, the residual within 10x the constraint tolerance.
void scored_rkmerson_runs(const std::string& problem, const std::vector<double>& accuracies, const std::string& t_end,
                          const std::string& every, std::map<double, std::map<std::string, std::string>>& rows) {
  for (const double accuracy : accuracies) {
    char acc[32];
    std::snprintf(acc, sizeof acc, "%.17g", accuracy);
    const std::string tag = problem + "-" + acc;
    const fs::path csv = scratch(tag + ".csv"), dir = scratch(tag);
    const Outcome o = peer("--problem " + problem + " --integrator rkmerson --accuracy " + acc + " --t-end " + t_end +
                           " --every " + every + " --out '" + csv.string() + "'");
    ASSERT_EQ(o.code, 0) << o.out;
    const Outcome s = score(problem, csv, dir);
    ASSERT_EQ(s.code, 0) << s.out;
    rows[accuracy] = summary(dir);
    const auto& row = rows[accuracy];
    EXPECT_EQ(row.at("status"), "ok") << tag;
    EXPECT_LE(std::stod(row.at("initial_state_deviation")), 4 * kEps) << tag;
    EXPECT_LE(std::stod(row.at("max_residual")), 10 * 0.1 * accuracy) << tag;
  }
}

TEST(SimbodyPeer, AndrewsScoredRunFollowsCstabsReference) {
  REQUIRE_PEER();
  std::map<double, std::map<std::string, std::string>> rows;
  ASSERT_NO_FATAL_FAILURE(scored_rkmerson_runs("andrews", {1e-3, 1e-6}, "0.03", "0.001", rows));
  EXPECT_LT(std::stod(rows[1e-6].at("max_residual")), std::stod(rows[1e-3].at("max_residual")));
  EXPECT_LT(std::stod(rows[1e-6].at("ref_error")), 1e-3);
  EXPECT_LT(std::stod(rows[1e-6].at("max_energy_drift")), 1e-3);
}

// cstab's car axis accelerations at (t, q, v): M a = Q + A^T lambda with
// A a + gamma = 0 (methods/mechanical.hpp), solved as one KKT system.
std::vector<double> car_axis_accelerations(double t, const double* c) {
  const cstab::CarAxis problem;
  cstab::Vec<double, 4> q, v;
  for (int i = 0; i < 4; ++i) q(i) = c[i], v(i) = c[4 + i];
  cstab::MechanicalTerms<cstab::CarAxisMechanical> terms;
  terms.evaluate(problem.mechanical(), t, q, v, false);
  Eigen::Matrix<double, 6, 6> kkt = Eigen::Matrix<double, 6, 6>::Zero();
  kkt.topLeftCorner<4, 4>() = terms.M;
  kkt.topRightCorner<4, 2>() = terms.A.transpose();
  kkt.bottomLeftCorner<2, 4>() = terms.A;
  Eigen::Matrix<double, 6, 1> rhs;
  rhs << terms.Q, -terms.gamma;
  const Eigen::Matrix<double, 6, 1> x = kkt.fullPivLu().solve(rhs);
  return {x(0), x(1), x(2), x(3)};
}

std::vector<double> numbers(const std::string& list) {
  std::vector<double> out;
  for (const auto& cell : split(list)) out.push_back(std::stod(cell));
  return out;
}

// The car axis (IVP Test Set): the columns are cstab's coordinates, the first
// row is the Test Set's initial state exactly, and Simbody's energy of it
// (kinetic, gravity's k g y, and both springs' (l - L0)^2 / 2, zero at the
// start) is the same restated from cstab's parameters. The start is at rest
// in every force but gravity (both springs at their free length, no
// constraint force), so the accelerations are also compared at the run's
// last row, (t, q, v) = the written values (%.17g, read back exactly): there
// the springs, the moving bump and both constraints' forces all act, and
// Simbody's udot equals cstab's KKT solution to round-off (measured 3e-14
// relative here, 1.4e-16 at t = 3; 3e-10 at accuracy 1e-3, where the state
// is further off the constraints and the two formulations' rows differ
// there).
TEST(SimbodyPeer, CarAxisStartsAtCstabsStateAndAccelerations) {
  REQUIRE_PEER();
  const cstab::CarAxis problem;
  const cstab::CarAxisParameters p;
  const fs::path csv = scratch("car-axis-start.csv");
  const Outcome o = peer("--problem car-axis --integrator rkmerson --accuracy 1e-9 --t-end 0.5 --every 0.1 --out '" +
                         csv.string() + "'");
  ASSERT_EQ(o.code, 0) << o.out;
  const Trajectory tr = read(csv);
  std::vector<std::string> columns = {"t"};
  for (const auto& name : problem.info().coordinates) columns.push_back(name);
  ASSERT_EQ(tr.columns, columns);
  ASSERT_EQ(tr.rows.size(), 6u);
  cstab::Vec<double, 4> q, v;
  problem.mechanical().initial_state(q, v);
  double c[8];
  problem.mechanical().to_canonical(0.0, q, v, c);
  EXPECT_EQ(tr.rows[0][0], 0.0);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(tr.rows[0][i + 1], c[i], 4 * kEps) << columns[i + 1];

  const double k = p.k(), g = p.g, L0 = p.L0;
  const double ll = std::hypot(c[0], c[1]), lr = std::hypot(c[2] - p.L, c[3]);  // the bump is at (L, 0) at t = 0
  const double e_cstab = 0.5 * k * (c[4] * c[4] + c[5] * c[5] + c[6] * c[6] + c[7] * c[7]) + k * g * (c[1] + c[3]) +
                         0.5 * (ll - L0) * (ll - L0) + 0.5 * (lr - L0) * (lr - L0);
  const double e_simbody = std::stod(tr.meta.at("simbody_initial_energy"));
  EXPECT_NEAR(e_cstab, 6.25e-4, 1e-15);
  EXPECT_NEAR(e_simbody, e_cstab, 16 * kEps * e_cstab) << "cstab " << e_cstab << ", Simbody " << e_simbody;

  const std::vector<double> a0 = car_axis_accelerations(0.0, c);
  const std::vector<double> a0_simbody = numbers(tr.meta.at("simbody_initial_accelerations"));
  ASSERT_EQ(a0_simbody.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(a0_simbody[i], a0[i], 16 * kEps * p.g) << columns[i + 1];

  const std::vector<double>& last = tr.rows.back();
  EXPECT_EQ(last[0], 0.5);
  const std::vector<double> a1 = car_axis_accelerations(last[0], last.data() + 1);
  const std::vector<double> a1_simbody = numbers(tr.meta.at("simbody_final_accelerations"));
  ASSERT_EQ(a1_simbody.size(), 4u);
  double scale = 1;
  for (const double a : a1) scale = std::max(scale, std::abs(a));
  EXPECT_GT(scale, 2.0);  // more than gravity acts
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(a1_simbody[i], a1[i], 1e-11 * scale) << columns[i + 1];
}

// The car axis over the Test Set's [0, 3], rows every 0.1 s (as the peers
// matrix), scored against its published solution at t = 3: the residual of
// cstab's two rows stays within 10x the constraint tolerance (measured up to
// 2.7x: the axle row is about 2 L times the length error Simbody's Rod
// measures) and shrinks from accuracy 1e-3 to 1e-6 (2.7e-4 to 2.7e-7), and
// at 1e-9 the run ends within 1e-5 of the reference (measured 2.2e-6).
TEST(SimbodyPeer, CarAxisScoredRunFollowsTheTestSetsSolution) {
  REQUIRE_PEER();
  std::map<double, std::map<std::string, std::string>> rows;
  ASSERT_NO_FATAL_FAILURE(scored_rkmerson_runs("car-axis", {1e-3, 1e-6, 1e-9}, "3", "0.1", rows));
  EXPECT_LT(std::stod(rows[1e-6].at("max_residual")), std::stod(rows[1e-3].at("max_residual")));
  EXPECT_LT(std::stod(rows[1e-9].at("ref_error")), 1e-5);
}

// The N four-bar (IFToMM A02), scored here rather than by `cstab score`
// (which has no observer for runtime-size problems): per row, the largest
// distance of the canonical state to cstab's reference, the largest of
// cstab's 2N + 1 bar rows (natural formulation) and |E - E(0)| with cstab's
// energy law.
struct NFourBarErrors {
  double ref_error = 0, residual = 0, energy_drift = 0, t_end = 0;
};

NFourBarErrors n_four_bar_errors(const cstab::NFourBar& problem, const Trajectory& tr) {
  NFourBarErrors e;
  const size_t nc = size_t(problem.canonical_size());
  std::vector<double> ref(nc), phi(size_t(problem.scalable().rows()));
  const double e0 = problem.energy(0.0, tr.rows.at(0).data() + 1);
  for (const auto& row : tr.rows) {
    EXPECT_EQ(row.size(), nc + 1);
    const double* c = row.data() + 1;
    EXPECT_TRUE(problem.reference(row[0], ref.data())) << row[0];
    for (size_t i = 0; i < nc; ++i) e.ref_error = std::max(e.ref_error, std::abs(c[i] - ref[i]));
    problem.scalable().holonomic(c, phi.data());
    for (const double r : phi) e.residual = std::max(e.residual, std::abs(r));
    e.energy_drift = std::max(e.energy_drift, std::abs(problem.energy(row[0], c) - e0));
    e.t_end = row[0];
  }
  return e;
}

cstab::NFourBar n_four_bar(int N) {
  cstab::NFourBarParameters p;
  p.N = N;
  return cstab::NFourBar(p);
}

// The N four-bar at the default N = 40 and at N = 3: the header is `t` plus
// `NFourBar::info().coordinates`, the first row is cstab's initial state
// (B_i = (i L, L), every B_i moving at (1, 0)) to round-off, and Simbody's
// energy of it (2N + 1 bars' kinetic energy plus m g y_centre each) is
// cstab's energy().
TEST(SimbodyPeer, NFourBarStartsAtCstabsStateAndEnergy) {
  REQUIRE_PEER();
  for (const int N : {40, 3}) {
    const cstab::NFourBar problem = n_four_bar(N);
    const cstab::NFourBarParameters& p = problem.parameters();
    const std::string tag = "n-four-bar-start-" + std::to_string(N);
    const fs::path csv = scratch(tag + ".csv");
    const std::string param = N == 40 ? "" : " --problem-param N=" + std::to_string(N);
    const Outcome o = peer("--problem n-four-bar" + param + " --integrator rkmerson --t-end 0.1 --every 0.1 --out '" +
                           csv.string() + "'");
    ASSERT_EQ(o.code, 0) << o.out;
    const Trajectory tr = read(csv);
    std::vector<std::string> columns = {"t"};
    for (const auto& name : problem.info().coordinates) columns.push_back(name);
    ASSERT_EQ(tr.columns, columns) << tag;
    ASSERT_EQ(tr.rows.size(), 2u);
    const int nc = problem.canonical_size(), n = nc / 2;
    std::vector<double> q(static_cast<size_t>(n)), v(q), c(static_cast<size_t>(nc));
    problem.scalable().initial_state(q.data(), v.data());
    problem.scalable().to_canonical(0.0, q.data(), v.data(), c.data());
    EXPECT_EQ(tr.rows[0][0], 0.0);
    // Simbody's start projection and its cos(pi/2) = 6e-17 move B_i by a few
    // eps of the largest coordinate, N L (measured up to 1.8e-15 at N = 40,
    // 6.1e-17 at N = 3).
    double deviation = 0;
    for (int i = 0; i < nc; ++i) {
      EXPECT_NEAR(tr.rows[0][size_t(i) + 1], c[size_t(i)], 4 * kEps * N * p.L) << tag << " " << columns[size_t(i) + 1];
      deviation = std::max(deviation, std::abs(tr.rows[0][size_t(i) + 1] - c[size_t(i)]));
    }
    // 2N + 1 bars' m g y_centre (and kinetic energies) summed: E = 620.3 at
    // N = 40 (measured equal to the last bit), 51.2 at N = 3 (1 ulp apart).
    const double e_cstab = problem.energy(0.0, c.data());
    const double e_simbody = std::stod(tr.meta.at("simbody_initial_energy"));
    EXPECT_GT(e_cstab, (2 * N + 1) * 0.5 * p.m * p.g * p.L);  // the cranks' m g L / 2 alone is less
    EXPECT_NEAR(e_simbody, e_cstab, 16 * kEps * e_cstab) << tag << ": cstab " << e_cstab << ", Simbody " << e_simbody;
    std::printf("n-four-bar N = %d: start deviation %.3g, energy cstab %.17g Simbody %.17g (diff %.3g)\n", N, deviation,
                e_cstab, e_simbody, e_simbody - e_cstab);
  }
}

// The N four-bar over the first 0.5 s (the cranks turn from vertical to 46.5
// degrees, B0 speeding from 1 to 1.9 m/s; the first singular position is at
// t = 0.72), N = 40, rkmerson, rows every 0.1 s. At accuracy 1e-8
// (constraint tolerance 1e-9) every row is within 1e-6 of cstab's reference
// (measured 9.4e-8; 2 % more mass in the couplers puts it 3.2e-3 off) and
// cstab's energy within 1e-5 of E(0) = 620.3 (measured 1.5e-6); at 1e-4 the
// error is larger (measured 5.2e-5). The bar rows stay within 10x the
// constraint tolerance (measured 1.4e-14 at both: the motion keeps the
// parallelogram, equal crank angles and couplers at minus them, a linear
// invariant of the Pins' q that Runge-Kutta steps keep to round-off).
TEST(SimbodyPeer, NFourBarShortRunFollowsCstabsReference) {
  REQUIRE_PEER();
  const cstab::NFourBar problem = n_four_bar(40);
  std::map<double, NFourBarErrors> errors;
  for (const double accuracy : {1e-4, 1e-8}) {
    char acc[32];
    std::snprintf(acc, sizeof acc, "%.17g", accuracy);
    const std::string tag = std::string("n-four-bar-") + acc;
    const fs::path csv = scratch(tag + ".csv");
    const Outcome o = peer("--problem n-four-bar --problem-param N=40 --integrator rkmerson --accuracy " +
                           std::string(acc) + " --t-end 0.5 --every 0.1 --out '" + csv.string() + "'");
    ASSERT_EQ(o.code, 0) << o.out;
    const Trajectory tr = read(csv);
    ASSERT_EQ(tr.rows.size(), 6u) << tag;
    errors[accuracy] = n_four_bar_errors(problem, tr);
    const NFourBarErrors& e = errors[accuracy];
    EXPECT_EQ(e.t_end, 0.5) << tag;
    EXPECT_LE(e.residual, 10 * 0.1 * accuracy) << tag;
    std::printf("n-four-bar N = 40 rkmerson %s to t = 0.5: ref error %.3g, max residual %.3g, max |dE| %.3g\n", acc,
                e.ref_error, e.residual, e.energy_drift);
  }
  EXPECT_LT(errors[1e-8].ref_error, 1e-6);
  EXPECT_LT(errors[1e-8].energy_drift, 1e-5);
  EXPECT_LT(errors[1e-8].ref_error, errors[1e-4].ref_error);
}

TEST(SimbodyPeer, BadInputExitsTwoWithOneLine) {
  REQUIRE_PEER();
  const fs::path csv = scratch("bad.csv");
  const std::string out = " --out '" + csv.string() + "'";
  const std::vector<std::string> bad = {
      "--problem wheel --integrator rk3" + out,
      "--problem pendulum --integrator rk4" + out,
      "--problem pendulum --integrator rk3 --accuracy 0" + out,
      "--problem pendulum --integrator rk3 --accuracy nan" + out,
      "--problem pendulum --integrator rk3 --constraint-tolerance -1" + out,
      "--problem pendulum --integrator rk3 --problem-param angle=500" + out,
      "--problem pendulum --integrator rk3 --problem-param mass=2" + out,
      "--problem slider-crank --integrator rk3 --problem-param a=0.4" + out,
      "--problem bricard --integrator rk3 --problem-param L=2" + out,
      "--problem bricard --integrator rk3 --closure loose" + out,
      "--problem andrews --integrator rk3 --problem-param c0=1" + out,
      "--problem andrews --integrator rk3 --closure redundant" + out,
      "--problem car-axis --integrator rk3 --problem-param eps=0.1" + out,
      "--problem car-axis --integrator rk3 --closure redundant" + out,
      "--problem n-four-bar --integrator rk3 --problem-param N=0" + out,
      "--problem n-four-bar --integrator rk3 --problem-param N=1001" + out,
      "--problem n-four-bar --integrator rk3 --problem-param N=2.5" + out,
      "--problem n-four-bar --integrator rk3 --problem-param M=2" + out,
      "--problem n-four-bar --integrator rk3 --closure redundant" + out,
      "--problem pendulum --integrator rk3 --closure redundant" + out,
      "--problem pendulum --integrator rk3 --t-end -1" + out,
      "--problem pendulum --integrator rk3",
      "--problem pendulum --integrator rk3 --out /nonexistent-dir/x.csv",
      "--problem pendulum --integrator rk3 --frobnicate 1" + out,
  };
  for (const auto& args : bad) {
    fs::remove(csv);
    const Outcome o = peer(args);
    EXPECT_EQ(o.code, 2) << args << ": " << o.out;
    EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 1) << args << ": " << o.out;
    EXPECT_EQ(o.out.rfind("cstab-peer-simbody: ", 0), 0u) << o.out;
    if (args.find("/nonexistent") == std::string::npos) {
      EXPECT_FALSE(fs::exists(csv)) << args;
    }
  }
}

// A constraint tolerance below round-off makes Simbody's projection fail:
// exit 1, the rows integrated so far written (and scoreable), the error said.
TEST(SimbodyPeer, SimbodyFailureWritesWhatWasIntegratedAndExitsOne) {
  REQUIRE_PEER();
  const fs::path csv = scratch("fail.csv");
  const Outcome o = peer("--problem pendulum --integrator rkmerson --constraint-tolerance 1e-18 --out '" +
                         csv.string() + "'");
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("Simbody failed"), std::string::npos) << o.out;
  const Trajectory tr = read(csv);
  ASSERT_GE(tr.rows.size(), 2u);
  EXPECT_LT(tr.rows.back()[0], 10.0);
  EXPECT_TRUE(tr.meta.count("simbody_error"));
  const Outcome s = score("pendulum", csv, scratch("fail-scored"));
  EXPECT_EQ(s.code, 0) << s.out;
}

}  // namespace

// Robustness (issue 9): failing and diverging runs are recorded results
// (status, time, reason in words), two runs of one case write identical
// series, and an interrupted matrix keeps every finished case and resumes
// to the same summary as an uninterrupted run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "matrix/matrix.hpp"
#include "harness/run.hpp"
#include "methods/baumgarte.hpp"
#include "methods/pesterev.hpp"
#include "methods/problem_adapter.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

namespace fs = std::filesystem;
using cstab::testing::Outcome;
using cstab::testing::quote;
using cstab::testing::slurp;

struct Scratch : cstab::testing::Scratch {
  Scratch() : cstab::testing::Scratch("cstab_robust") {}
};

std::string field(const RunResult& r, const std::string& column) {
  for (const auto& [k, v] : r.summary_row())
    if (k == column) return v;
  return "(no column " + column + ")";
}

RunResult run(const std::string& problem, const std::string& method, const std::string& integrator, double setting,
              double t_end, std::vector<std::pair<std::string, std::string>> params = {}, double blowup = 1e3) {
  RunConfig cfg;
  cfg.problem = problem;
  cfg.method = method;
  cfg.integrator = integrator;
  if (find_integrator(integrator).fixed_step)
    cfg.step.step = setting;
  else
    cfg.step.rtol = cfg.step.atol = setting;
  cfg.t_end = t_end;
  cfg.params = std::move(params);
  cfg.blowup = blowup;
  cfg.ref_time = 0;
  cfg.write_series = false;
  return run_case(find_problem(problem), cfg, "");
}

// The summary row says what happened, when, and why, in words.
void expect_recorded(const RunResult& r, const std::string& status, const std::string& reason_part) {
  EXPECT_EQ(field(r, "status"), status) << r.reason;
  EXPECT_NE(r.reason.find(reason_part), std::string::npos) << "reason: " << r.reason;
  EXPECT_EQ(field(r, "reason"), r.reason);
  EXPECT_TRUE(std::isfinite(r.fail_time)) << r.reason;
  EXPECT_GE(r.fail_time, 0);
  EXPECT_LT(r.t_reached, r.t_end);
  EXPECT_FALSE(field(r, "fail_time").empty());
}

// ---------------------------------------------------------------------------
// Diverging and failing runs, provoked for real.

// RK4's real stability interval is 2.785: h * lambda = 30 makes Pesterev's
// feedback explode; the residual check stops it.
TEST(FailingRuns, AbsurdGainIsAResidualBlowUp) {
  const RunResult r = run("wheel", "pesterev", "rk4", 1e-3, 1, {{"lambda", "30000"}});
  expect_recorded(r, "diverged", "above");
  EXPECT_GT(r.max_residual, 1e3);
}

// Baumgarte with gains far beyond explicit Euler's stability, and the
// residual check out of the way: the state itself overflows to inf/NaN and
// is caught as such. (On the slider-crank, whose constraint rows keep full
// rank everywhere; on the wheel the exploding state first makes the
// reaction matrix singular, which is recorded as "failed".)
TEST(FailingRuns, AbsurdGainWithoutBlowupLimitIsANonFiniteState) {
  const RunResult r = run("slider-crank", "baumgarte", "euler", 1e-2, 1, {{"alpha", "1e5"}, {"beta", "1e5"}}, 1e308);
  expect_recorded(r, "diverged", "non-finite");
}

// A tolerance far below machine precision: GSL can only shrink the step.
TEST(FailingRuns, ImpossibleToleranceIsAStepSizeUnderflow) {
  const RunResult r = run("wheel", "pesterev", "rk8pd", 1e-300, 1);
  expect_recorded(r, "failed", "step");
  EXPECT_EQ(r.reason.find("GSL: failure"), std::string::npos) << "a GSL code without words: " << r.reason;
}

// IDA's error codes come back in words (not "flag -3").
TEST(FailingRuns, IdaFailureIsTranslatedIntoWords) {
  const RunResult r = run("slider-crank", "ida-ggl", "ida", 1e-300, 1);
  EXPECT_EQ(r.status, "failed") << r.reason;
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.reason.find("flag"), std::string::npos) << r.reason;
  EXPECT_TRUE(std::isfinite(r.fail_time));
}

// A point mass on the cross x * y = 0 moving along the x axis towards the
// origin, where the constraint gradient (y, x) vanishes: the reaction
// matrix becomes exactly singular at t = 1 (x = 1 - t, exact in binary
// with h = 1/64).
class CrossModel {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;
  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const { return {{"cross", "holonomic", "x y"}}; }
  template <class S>
  void mass(const S&, const Vec<S, 2>&, Eigen::Matrix<S, 2, 2>& M) const {
    M.setIdentity();
  }
  template <class S>
  void forces(const S&, const Vec<S, 2>&, const Vec<S, 2>&, Vec<S, 2>& Q) const {
    Q.setZero();
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) * q(1);
  }
  template <class S>
  S energy(const S&, const Vec<S, 2>&, const Vec<S, 2>& v) const {
    return 0.5 * v.dot(v);
  }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << 1.0, 0.0;
    v << -1.0, 0.0;
  }
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
};

class Cross {
 public:
  ProblemInfo info() const {
    ProblemInfo i;
    i.name = "cross";
    i.coordinates = {"x", "y", "xdot", "ydot"};
    i.has_energy = true;
    i.default_t_end = 2;
    return i;
  }
  const CrossModel& mechanical() const { return model_; }
  double energy(double, const double* c) const { return 0.5 * (c[2] * c[2] + c[3] * c[3]); }

 private:
  CrossModel model_;
};

TEST(FailingRuns, SingularReactionMatrixDuringTheRun) {
  static const std::unique_ptr<Problem> cross_problem = adapt_with_methods<Cross, BaumgarteMethod, PesterevMethod>(Cross{});
  const Problem& cross = *cross_problem;
  for (const std::string method : {"baumgarte", "pesterev"}) {
    SCOPED_TRACE(method);
    RunConfig cfg;
    cfg.problem = "cross";
    cfg.method = method;
    cfg.integrator = "rk4";
    cfg.step.step = 1.0 / 64;
    cfg.t_end = 2;
    cfg.ref_time = 0;
    cfg.write_series = false;
    const RunResult r = run_case(cross, cfg, "");
    expect_recorded(r, "failed", "singular");
    // The last good state is the step before the origin.
    EXPECT_NEAR(r.fail_time, 1.0 - 1.0 / 64, 1e-12) << r.reason;
  }
}

// ---------------------------------------------------------------------------
// The binary.

Outcome sh(const std::string& command) { return cstab::testing::run_shell(command); }

// A matrix with a diverging, a failing and a good case goes on to the end
// and records each with its status and reason.
TEST(FailingRuns, MatrixRecordsEveryOutcomeAndGoesOn) {
  Scratch s;
  std::ofstream(s.dir() / "m.toml") << R"([defaults]
problems = ["wheel"]
methods = ["pesterev"]
t_end = 0.2
ref_time = 0

[[sweep]]
name = "blowup"
integrators = "rk4"
step = 1e-3
param.lambda = [30000, 100]

[[sweep]]
name = "underflow"
integrators = "rk8pd"
tol = 1e-300
)";
  const Outcome o = sh(quote(CSTAB_BINARY) + " matrix " + quote((s.dir() / "m.toml").string()) + " --out " +
                       quote((s.dir() / "out").string()) + " --jobs 2 --no-report");
  ASSERT_EQ(o.code, 0) << o.out;
  const CsvTable t = read_csv((s.dir() / "out" / "summary.csv").string());
  ASSERT_EQ(t.rows.size(), 3u) << o.out;
  std::map<std::string, std::string> status_of;  // params or sweep -> status
  for (size_t i = 0; i < t.rows.size(); ++i) {
    const std::string params = t.get(i, "params");
    const std::string key = t.get(i, "sweep") + " " + params.substr(0, params.find(';'));
    status_of[key] = t.get(i, "status");
    if (t.get(i, "status") != "ok") {
      EXPECT_FALSE(t.get(i, "reason").empty()) << key;
      EXPECT_FALSE(t.get(i, "fail_time").empty()) << key;
    }
  }
  EXPECT_EQ(status_of["blowup lambda=30000"], "diverged");
  EXPECT_EQ(status_of["blowup lambda=100"], "ok");
  EXPECT_EQ(status_of["underflow lambda=6"], "failed");
  EXPECT_NE(o.out.find("1 diverged, 1 failed, 1 ok"), std::string::npos) << o.out;
}

// ---------------------------------------------------------------------------
// Determinism: the same case twice gives byte-identical series.

TEST(Determinism, TwoRunsWriteIdenticalSeries) {
  Scratch s;
  const std::vector<std::string> cases = {
      "--problem wheel --method pesterev --integrator adams --step 1e-3 --t-end 0.5",
      "--problem wheel --method pesterev --integrator rk8pd --rtol 1e-9 --atol 1e-9 --t-end 0.5",
      "--problem ball --method projection --integrator rk8pd --rtol 1e-8 --atol 1e-8 --t-end 0.5",
      "--problem biped --method braun-goldfarb --integrator rk4 --step 1e-3 --t-end 0.2",
      "--problem andrews --method baumgarte --integrator msbdf --rtol 1e-7 --atol 1e-7 --t-end 0.003",
      "--problem slider-crank --method ida-ggl --integrator ida --rtol 1e-8 --atol 1e-8 --t-end 0.5",
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i]);
    std::string series[2];
    for (int k = 0; k < 2; ++k) {
      const fs::path out = s.dir() / (std::to_string(i) + "_" + std::to_string(k));
      const Outcome o = sh(quote(CSTAB_BINARY) + " run " + cases[i] + " --out " + quote(out.string()));
      ASSERT_EQ(o.code, 0) << o.out;
      series[k] = slurp(out / "series.csv");
    }
    EXPECT_GT(std::count(series[0].begin(), series[0].end(), '\n'), 10);
    EXPECT_TRUE(series[0] == series[1]) << "series differ between two runs of the same case";
  }
}

// In a forked child before exec: the default actions for the signals the
// tests send (a background job of a non-interactive shell inherits SIGINT
// ignored, and cstab rightly keeps it so).
void default_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::signal(sig, SIG_DFL);
}

// ---------------------------------------------------------------------------
// An interrupted `cstab run` leaves neither a half-written file nor a
// temporary: it dies of the signal with an empty output folder.

TEST(Interrupt, RunLeavesNoFileBehind) {
  for (int sig : {SIGINT, SIGTERM}) {
    SCOPED_TRACE(sig);
    Scratch s;
    const fs::path out = s.dir() / "out";
    const pid_t pid = ::fork();
    if (pid == 0) {
      default_signals();
      const int fd = ::open("/dev/null", O_WRONLY);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::execl(CSTAB_BINARY, CSTAB_BINARY, "run", "--problem", "wheel", "--method", "pesterev", "--integrator", "rk4",
              "--step", "1e-5", "--t-end", "200", "--sample-every", "1e-4", "--out", out.c_str(),
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Wait until the temporaries exist (the run is integrating), then signal.
    bool writing = false;
    for (int i = 0; i < 20000 && !writing; ++i) {
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(out, ec))
        if (e.path().filename().string().find(".tmp.") != std::string::npos) writing = true;
      if (!writing) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    EXPECT_TRUE(writing);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(out)) left.push_back(e.path().filename().string());
    EXPECT_TRUE(left.empty()) << left.front();
  }
}

// ---------------------------------------------------------------------------
// Interruption: SIGINT to the process group (Ctrl-C) and SIGTERM to the
// matrix process alone both keep every finished case; the rerun resumes and
// ends with the summary of an uninterrupted run, timing columns aside.

const char* kInterruptMatrix = R"(# about 20 cases of ~0.1 s each
[defaults]
problems = ["wheel"]
methods = ["pesterev", "baumgarte", "none", "projection", "minimal"]
t_end = 1
ref_time = 1

[[sweep]]
name = "fixed"
integrators = "rk4"
step = [4e-4, 3e-4, 2e-4]

[[sweep]]
name = "adaptive"
integrators = "rk8pd"
tol = 1e-11
)";


size_t finished_cases(const fs::path& out) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "cases", ec))
    if (fs::exists(e.path() / "case.txt")) ++n;
  return n;
}

class MatrixInterrupt : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new Scratch;
    std::ofstream(dir_->dir() / "m.toml") << kInterruptMatrix;
    const auto start = std::chrono::steady_clock::now();
    full_ = sh(command("full"));
    full_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string command(const std::string& out) {
    return quote(CSTAB_BINARY) + " matrix " + quote((dir_->dir() / "m.toml").string()) + " --out " +
           quote((dir_->dir() / out).string()) + " --jobs 2 --no-report";
  }

  // Starts `cstab matrix TOML --out OUT --jobs JOBS --no-report` in its own
  // process group, output to LOG.
  static pid_t spawn(const fs::path& toml, const fs::path& out, const std::string& jobs, const fs::path& log) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::setpgid(0, 0);
      default_signals();
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::execl(CSTAB_BINARY, CSTAB_BINARY, "matrix", toml.c_str(), "--out", out.c_str(), "--jobs", jobs.c_str(),
              "--no-report", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::setpgid(pid, pid);
    return pid;
  }

  // Runs the matrix, waits until `after` cases have finished, sends `sig`
  // (to the whole group if `group`), and waits for the end.
  static void interrupt(const std::string& name, int sig, bool group, size_t after, int* code, std::string* log) {
    const fs::path out = dir_->dir() / name, log_path = dir_->dir() / (name + ".log");
    const pid_t pid = spawn(dir_->dir() / "m.toml", out, "2", log_path);
    int status = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    bool sent = false;
    while (true) {
      if (::waitpid(pid, &status, WNOHANG) == pid) break;
      if (!sent && finished_cases(out) >= after) {
        ::kill(group ? -pid : pid, sig);
        sent = true;
      }
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(-pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    *log = slurp(log_path);
  }

  void check_interrupted_then_resumed(const std::string& name, int sig, bool group, int expected_code,
                                      const std::string& signal_name) {
    ASSERT_EQ(full_.code, 0) << full_.out;
    const size_t total = read_csv((dir_->dir() / "full" / "cases.csv").string()).rows.size();
    ASSERT_GE(total, 10u);
    int code = -1;
    std::string log;
    interrupt(name, sig, group, 3, &code, &log);
    const fs::path out = dir_->dir() / name;
    EXPECT_EQ(code, expected_code) << log;
    EXPECT_NE(log.find("interrupted by " + signal_name), std::string::npos) << log;
    EXPECT_NE(log.find("run the same command again to resume"), std::string::npos) << log;
    // Every finished case kept, nothing half-written left.
    const size_t kept = finished_cases(out);
    EXPECT_GE(kept, 3u) << log;
    ASSERT_LT(kept, total) << "the interruption came after the end (full run: " << full_seconds_ << " s)\n" << log;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
      if (e.is_directory() && e.path().parent_path().filename() == "cases") {
        EXPECT_TRUE(fs::exists(e.path() / "case.txt")) << "unfinished case folder left: " << e.path();
      }
    }
    // The summary of what finished: one row per finished case.
    const CsvTable partial = read_csv((out / "summary.csv").string());
    EXPECT_EQ(partial.rows.size(), kept);
    for (size_t r = 0; r < partial.rows.size(); ++r) {
      EXPECT_TRUE(fs::exists(out / "cases" / partial.get(r, "case_id") / "case.txt"));
      EXPECT_NE(partial.get(r, "status"), "crashed") << "an interrupted worker recorded as a crash";
    }
    // Resume.
    const Outcome again = sh(command(name));
    ASSERT_EQ(again.code, 0) << again.out;
    EXPECT_NE(again.out.find(std::to_string(kept) + " of " + std::to_string(total) + " cases cached"),
              std::string::npos)
        << again.out;
    EXPECT_NE(again.out.find(std::to_string(total - kept) + " run, " + std::to_string(kept) + " cached"),
              std::string::npos)
        << again.out;
    EXPECT_EQ(cstab::testing::summary_without_timing(out / "summary.csv"),
              cstab::testing::summary_without_timing(dir_->dir() / "full" / "summary.csv"));
  }

  static Scratch* dir_;
  static Outcome full_;
  static double full_seconds_;
};
Scratch* MatrixInterrupt::dir_ = nullptr;
Outcome MatrixInterrupt::full_;
double MatrixInterrupt::full_seconds_ = 0;

TEST_F(MatrixInterrupt, CtrlCToTheProcessGroupKeepsFinishedCasesAndResumes) {
  check_interrupted_then_resumed("sigint", SIGINT, true, 130, "SIGINT");
}

TEST_F(MatrixInterrupt, SigtermToTheMatrixProcessKeepsFinishedCasesAndResumes) {
  check_interrupted_then_resumed("sigterm", SIGTERM, false, 143, "SIGTERM");
}

// A worker killed from outside is an unfinished case, not a `crashed`
// result: the matrix goes on, says so (exit 1), and the rerun completes it.
TEST_F(MatrixInterrupt, WorkerKilledFromOutsideIsUnfinishedNotCrashed) {
  ASSERT_EQ(full_.code, 0) << full_.out;
  Scratch s;
  std::ofstream(s.dir() / "one.toml") << R"([[sweep]]
problems = ["wheel"]
methods = ["pesterev"]
integrators = "rk4"
step = 1e-5
t_end = 20
ref_time = 0
series = false
)";
  const pid_t pid = spawn(s.dir() / "one.toml", s.dir() / "out", "1", s.dir() / "log");
  // Kill the worker once it runs: the matrix process's child that is the
  // cstab binary itself (a fork), not a helper such as the shells that
  // collect the provenance.
  const fs::path binary = fs::canonical(CSTAB_BINARY);
  bool killed = false;
  for (int i = 0; i < 4000 && !killed; ++i) {
    std::error_code ec;
    // The case folder is created just before the worker is forked (and
    // after the provenance helpers have finished).
    if (fs::is_empty(s.dir() / "out" / "cases", ec) || ec) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    for (pid_t w : cstab::testing::children_running(pid, binary)) killed = ::kill(w, SIGTERM) == 0 || killed;
    if (!killed) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_TRUE(killed);
  int status = 0;
  ::waitpid(pid, &status, 0);
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = slurp(s.dir() / "log");
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("worker stopped by SIGTERM"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("1 of 1 cases unfinished"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(s.dir() / "out" / "cases" / read_csv((s.dir() / "out" / "cases.csv").string()).get(0, "case_id")));
  EXPECT_EQ(read_csv((s.dir() / "out" / "summary.csv").string()).rows.size(), 0u);
}

}  // namespace
}  // namespace cstab

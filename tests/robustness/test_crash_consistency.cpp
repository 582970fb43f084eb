// Crash consistency of a results folder (issue 16, ctest label
// `robustness`): kill -9 the matrix process or one of its workers at random
// points of a small matrix, run two matrices on one folder, damage cached
// files; after each fault a plain rerun must end with a summary.csv equal to
// an uninterrupted run's (timing columns aside), no worker may outlive its
// matrix, and no temporary file may remain. Bounded: about a minute.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "matrix/matrix.hpp"
#include "tests/support/test_util.hpp"

namespace fs = std::filesystem;
using cstab::testing::quote;
using cstab::testing::Scratch;
using cstab::testing::slurp;
using cstab::testing::summary_without_timing;

namespace {

using Clock = std::chrono::steady_clock;

// Six cases of a few tenths of a second each.
const char* kMatrix = R"([[sweep]]
problems = ["wheel"]
methods = ["pesterev", "baumgarte"]
integrators = "rk4"
step = [4e-4, 2e-4, 1e-4]
t_end = 20
)";

pid_t spawn_matrix(const fs::path& toml, const fs::path& out, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(CSTAB_BINARY, CSTAB_BINARY, "matrix", toml.c_str(), "--out", out.c_str(), "--jobs", "2",
            "--no-report", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::setpgid(pid, pid);
  return pid;
}

int wait_code(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The pids whose parent is `parent` and whose executable is the cstab binary.
std::vector<pid_t> workers_of(pid_t parent) {
  std::vector<pid_t> found;
  const fs::path binary = fs::canonical(CSTAB_BINARY);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 1));
    std::string state;
    long ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent && state != "Z" && fs::read_symlink(e.path() / "exe", ec) == binary)
      found.push_back(pid_t(std::stol(name)));
  }
  return found;
}

// Every process whose executable is the binary and whose command line
// names `out` (workers of a dead matrix are re-parented, so not by ppid).
size_t processes_on(const fs::path& out) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmdline = slurp(e.path() / "cmdline");
    for (char& c : cmdline)
      if (c == '\0') c = ' ';
    std::ifstream stat(e.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const size_t close = line.rfind(')');
    if (close != std::string::npos && line.substr(close + 2, 1) == "Z") continue;
    if (cmdline.find(" --out " + out.string() + " ") != std::string::npos) ++n;
  }
  return n;
}

size_t temporaries(const fs::path& dir) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) ++n;
  return n;
}

class CrashConsistency : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new Scratch("cstab_crash");
    std::ofstream(dir_->dir() / "m.toml") << kMatrix;
    const auto start = Clock::now();
    const pid_t pid = spawn_matrix(dir_->dir() / "m.toml", dir_->dir() / "full", dir_->dir() / "full.log");
    full_code_ = wait_code(pid);
    full_seconds_ = std::chrono::duration<double>(Clock::now() - start).count();
    seed_ = unsigned(std::random_device{}());
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path toml() { return dir_->dir() / "m.toml"; }
  static std::string expected() { return summary_without_timing(dir_->dir() / "full" / "summary.csv"); }

  // Reruns to the end and compares with the uninterrupted run.
  static void rerun_and_compare(const fs::path& out) {
    const pid_t pid = spawn_matrix(toml(), out, out.string() + ".rerun.log");
    const int code = wait_code(pid);
    ASSERT_EQ(code, 0) << slurp(out.string() + ".rerun.log");
    EXPECT_EQ(summary_without_timing(out / "summary.csv"), expected());
    EXPECT_EQ(temporaries(out), 0u);
  }

  static Scratch* dir_;
  static int full_code_;
  static double full_seconds_;
  static unsigned seed_;
};
Scratch* CrashConsistency::dir_ = nullptr;
int CrashConsistency::full_code_ = -1;
double CrashConsistency::full_seconds_ = 0;
unsigned CrashConsistency::seed_ = 0;

TEST_F(CrashConsistency, KillNineOfTheMatrixAtRandomPointsLeavesNoWorkerAndResumes) {
  ASSERT_EQ(full_code_, 0) << slurp(dir_->dir() / "full.log");
  std::mt19937 rng(seed_);
  std::uniform_real_distribution<double> when(0.05, std::max(0.1, 0.9 * full_seconds_));
  for (int round = 0; round < 3; ++round) {
    const double delay = when(rng);
    SCOPED_TRACE("seed " + std::to_string(seed_) + ", round " + std::to_string(round) + ", kill -9 after " +
                 std::to_string(delay) + " s of a " + std::to_string(full_seconds_) + " s run");
    const fs::path out = dir_->dir() / ("parent" + std::to_string(round));
    const pid_t pid = spawn_matrix(toml(), out, out.string() + ".log");
    std::this_thread::sleep_for(std::chrono::duration<double>(delay));
    ::kill(pid, SIGKILL);  // the matrix process only: its workers must follow
    wait_code(pid);
    // The workers die with their parent (PR_SET_PDEATHSIG).
    // (0.5 s: far less than the cases still running would need.)
    const auto deadline = Clock::now() + std::chrono::milliseconds(500);
    while (processes_on(out) > 0 && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_EQ(processes_on(out), 0u) << "a worker outlived its matrix";
    rerun_and_compare(out);
  }
}

TEST_F(CrashConsistency, KillNineOfAWorkerIsNotRecordedAndTheRerunCompletes) {
  ASSERT_EQ(full_code_, 0);
  const fs::path out = dir_->dir() / "worker";
  const pid_t pid = spawn_matrix(toml(), out, out.string() + ".log");
  bool killed = false;
  for (int i = 0; i < 5000 && !killed; ++i) {
    // Only once a case folder exists: before, a child of the matrix may be
    // a provenance helper between its fork and its exec.
    std::error_code ec;
    if (fs::is_empty(out / "cases", ec) || ec) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    for (pid_t w : workers_of(pid)) killed = ::kill(w, SIGKILL) == 0 || killed;
    if (!killed) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_TRUE(killed);
  const int code = wait_code(pid);
  const std::string log = slurp(out.string() + ".log");
  EXPECT_EQ(code, 1) << log;
  EXPECT_NE(log.find("NOT RECORDED"), std::string::npos) << log;
  EXPECT_NE(log.find("not recorded (a worker crashed, was killed from outside"), std::string::npos) << log;
  const cstab::CsvTable partial = cstab::read_csv((out / "summary.csv").string());
  for (size_t r = 0; r < partial.rows.size(); ++r) EXPECT_NE(partial.get(r, "status"), "crashed");
  rerun_and_compare(out);
}

TEST_F(CrashConsistency, TwoMatricesOnOneFolderTheSecondIsRefusedAtOnce) {
  ASSERT_EQ(full_code_, 0);
  const fs::path out = dir_->dir() / "two";
  const pid_t first = spawn_matrix(toml(), out, out.string() + ".first.log");
  // Wait until the first holds the folder.
  for (int i = 0; i < 2000 && !fs::exists(out / "cases.csv"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const auto start = Clock::now();
  const pid_t second = spawn_matrix(toml(), out, out.string() + ".second.log");
  const int second_code = wait_code(second);
  const double second_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const std::string log = slurp(out.string() + ".second.log");
  EXPECT_EQ(second_code, 2) << log;
  EXPECT_NE(log.find("in use by another cstab command (pid " + std::to_string(first) + " cstab matrix)"),
            std::string::npos)
      << log;
  EXPECT_LT(second_seconds, 5.0);
  EXPECT_EQ(wait_code(first), 0) << slurp(out.string() + ".first.log");
  EXPECT_EQ(summary_without_timing(out / "summary.csv"), expected());
}

TEST_F(CrashConsistency, DamagedCachedFilesAreRerunToTheSameSummary) {
  ASSERT_EQ(full_code_, 0);
  const fs::path out = dir_->dir() / "damaged";
  fs::copy(dir_->dir() / "full", out, fs::copy_options::recursive);
  const cstab::CsvTable cases = cstab::read_csv((out / "cases.csv").string());
  ASSERT_GE(cases.rows.size(), 6u);
  auto folder = [&](size_t i) { return out / "cases" / cases.get(i, "case_id"); };
  fs::resize_file(folder(0) / "series.csv.gz", 100);                             // truncated
  std::ofstream(folder(1) / "summary.csv", std::ios::app) << "\n";            // edited
  fs::remove(folder(2) / "series.csv.gz");                                      // deleted
  fs::remove(folder(3) / "summary.csv");                                     // deleted
  fs::rename(folder(4) / "series.csv.gz", dir_->dir() / "s4.csv");              // swapped
  fs::copy_file(folder(5) / "series.csv.gz", folder(4) / "series.csv.gz");
  fs::rename(dir_->dir() / "s4.csv", folder(5) / "series.csv.gz");
  fs::remove(out / "summary.csv");
  const pid_t pid = spawn_matrix(toml(), out, out.string() + ".log");
  ASSERT_EQ(wait_code(pid), 0) << slurp(out.string() + ".log");
  const std::string log = slurp(out.string() + ".log");
  size_t reruns = 0;
  for (size_t p = log.find("matrix: rerun "); p != std::string::npos; p = log.find("matrix: rerun ", p + 1)) ++reruns;
  EXPECT_EQ(reruns, 6u) << log;
  EXPECT_NE(log.find("6 run, 0 cached"), std::string::npos) << log;
  EXPECT_EQ(summary_without_timing(out / "summary.csv"), expected());
}

}  // namespace

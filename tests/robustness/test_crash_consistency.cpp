// Crash consistency of a results folder (issue 16, ctest label
// `robustness`): kill -9 the matrix process or one of its workers at 20
// random points of a small matrix (seeded; the seed is printed, and
// CSTAB_CRASH_SEED=N replays it), fill the disk (a small tmpfs), run two
// matrices on one folder, damage cached files; after each fault a plain
// rerun must end with a summary.csv equal to an uninterrupted run's (timing
// columns aside), a run that reports success must hold every case and only
// right ones, no worker may outlive its matrix, and no temporary file may
// remain. Bounded: each test a few seconds to about half a minute.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
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

// Six cases of a few hundredths to a tenth of a second each (about half a
// second in all): the smallest matrix with several cases per worker (2
// workers), each with a series file large enough to fill a small disk.
// (t_end below the wheel's reference time: no reference to compute.)
const char* kMatrix = R"([[sweep]]
problems = ["wheel"]
methods = ["pesterev", "baumgarte"]
integrators = "rk4"
step = [4e-4, 2e-4, 1e-4]
t_end = 3
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
  return cstab::testing::children_running(parent, fs::canonical(CSTAB_BINARY));
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

// Whether every row of `partial` is, cell by cell (timing columns aside),
// the row of the same case and repeat in `full`: a run that stopped early
// may lack cases, never hold a wrong one. (Its columns are the union over
// the cases it has, so a column it lacks must be empty in `full` there.)
bool rows_are_a_subset(const fs::path& partial, const fs::path& full) {
  const cstab::CsvTable p = cstab::read_csv(partial.string()), f = cstab::read_csv(full.string());
  auto timing = [](const std::string& column) {
    return column.size() > 8 && column.compare(column.size() - 8, 8, "_seconds") == 0;
  };
  for (size_t i = 0; i < p.rows.size(); ++i) {
    size_t j = 0;
    while (j < f.rows.size() &&
           (f.get(j, "case_id") != p.get(i, "case_id") || f.get(j, "repeat") != p.get(i, "repeat")))
      ++j;
    if (j == f.rows.size()) return false;
    for (const std::string& column : f.header)
      if (!timing(column) && p.get(i, column) != f.get(j, column))
        return false;
    for (const std::string& column : p.header)
      if (f.column(column) < 0) return false;
  }
  return true;
}

// Every case folder below `out`/cases that has no case.txt (half-written).
std::vector<std::string> unfinished_case_folders(const fs::path& out) {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "cases", ec))
    if (e.is_directory() && !fs::exists(e.path() / "case.txt")) found.push_back(e.path().filename().string());
  return found;
}

size_t case_folders(const fs::path& out) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "cases", ec)) n += e.is_directory();
  return n;
}

// The exit code of `pid` if it has ended (reaped), else -1.
int exit_code_if_ended(pid_t pid) {
  int status = 0;
  if (::waitpid(pid, &status, WNOHANG) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A tmpfs of a given size mounted on `dir` (created) while alive: a small
// disk to fill. Mounting needs CAP_SYS_ADMIN; without it (EPERM), a user
// and mount namespace of this process's own is tried (`unshare -Urm`);
// `why_not()` says why neither worked. Unmounted when destroyed.
class SmallDisk {
 public:
  SmallDisk(const fs::path& dir, size_t bytes) : dir_(dir) {
    fs::create_directories(dir_);
    if (mount_tmpfs(bytes)) return;
    const int err = errno;
    if (err != EPERM && err != EACCES) {
      why_not_ = std::string("mount -t tmpfs: ") + std::strerror(err);
      return;
    }
    if (!enter_own_namespace()) {
      why_not_ = std::string("mount -t tmpfs: ") + std::strerror(err) +
                 ", and no user namespace to mount it in (unshare -Urm: " + std::strerror(errno) + ")";
      return;
    }
    if (!mount_tmpfs(bytes))
      why_not_ = std::string("mount -t tmpfs in a user namespace: ") + std::strerror(errno);
  }
  ~SmallDisk() {
    if (mounted_ && ::umount2(dir_.c_str(), 0) != 0) ::umount2(dir_.c_str(), MNT_DETACH);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;

  bool mounted() const { return mounted_; }
  const std::string& why_not() const { return why_not_; }
  // More space, the files kept (mount -o remount,size=...).
  bool grow(size_t bytes) {
    const std::string options = "size=" + std::to_string(bytes);
    return ::mount("tmpfs", dir_.c_str(), "tmpfs", MS_REMOUNT, options.c_str()) == 0;
  }

 private:
  bool mount_tmpfs(size_t bytes) {
    const std::string options = "size=" + std::to_string(bytes) + ",mode=0755";
    mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, options.c_str()) == 0;
    return mounted_;
  }
  // unshare -Urm: root of a user namespace of our own, with a private mount table.
  static bool enter_own_namespace() {
    const uid_t uid = ::getuid();
    const gid_t gid = ::getgid();
    if (::unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0) return false;
    std::ofstream("/proc/self/setgroups") << "deny";
    std::ofstream("/proc/self/uid_map") << "0 " << uid << " 1";
    std::ofstream("/proc/self/gid_map") << "0 " << gid << " 1";
    return ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) == 0;
  }

  fs::path dir_;
  bool mounted_ = false;
  std::string why_not_;
};

class CrashConsistency : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new Scratch("cstab_crash");
    std::ofstream(dir_->dir() / "m.toml") << kMatrix;
    const auto start = Clock::now();
    const pid_t pid = spawn_matrix(dir_->dir() / "m.toml", dir_->dir() / "full", dir_->dir() / "full.log");
    full_code_ = wait_code(pid);
    full_seconds_ = std::chrono::duration<double>(Clock::now() - start).count();
    const char* replay = std::getenv("CSTAB_CRASH_SEED");
    seed_ = replay && *replay ? unsigned(std::strtoul(replay, nullptr, 10)) : unsigned(std::random_device{}());
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path toml() { return dir_->dir() / "m.toml"; }
  static std::string expected() { return summary_without_timing(dir_->dir() / "full" / "summary.csv"); }

  // Reruns to the end and compares with the uninterrupted run; whether all agreed.
  static bool rerun_and_compare(const fs::path& out) {
    const pid_t pid = spawn_matrix(toml(), out, out.string() + ".rerun.log");
    const int code = wait_code(pid);
    EXPECT_EQ(code, 0) << slurp(out.string() + ".rerun.log");
    const std::string summary = summary_without_timing(out / "summary.csv");
    EXPECT_EQ(summary, expected());
    EXPECT_EQ(temporaries(out), 0u);
    return code == 0 && summary == expected() && temporaries(out) == 0;
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

// 20 faults: kill -9 of the matrix process or of one of its workers (a
// coin toss), each after a random delay up to the shortest run seen, each
// into a fresh folder (a fault that came after the run's end is replaced,
// up to 60 rounds). A faulted run that still exits 0
// must hold the full summary; one that does not must hold only right rows
// (no case recorded wrongly); its rerun must end with the full summary.
TEST_F(CrashConsistency, KillNineOfTheMatrixOrAWorkerAtTwentyRandomPointsThenTheRerunMatches) {
  ASSERT_EQ(full_code_, 0) << slurp(dir_->dir() / "full.log");
  constexpr int kFaults = 20;
  {  // The row check below tells a wrong row from a right one.
    const fs::path full = dir_->dir() / "full" / "summary.csv", edited = dir_->dir() / "edited.csv";
    std::string text = slurp(full);
    const size_t row = text.find('\n') + 1;
    text.erase(row, text.find('\n', row) + 1 - row);  // one case fewer: still a subset
    std::ofstream(edited) << text;
    ASSERT_TRUE(rows_are_a_subset(edited, full));
    text.replace(text.find(",ok,"), 4, ",failed,");  // a case recorded wrongly
    std::ofstream(edited) << text;
    ASSERT_FALSE(rows_are_a_subset(edited, full));
  }
  std::cout << "crash-consistency: seed " << seed_ << " (replay: CSTAB_CRASH_SEED=" << seed_ << "), " << kFaults
            << " faults, delays below a " << full_seconds_ << " s run at first\n";
  std::mt19937 rng(seed_);
  std::bernoulli_distribution of_a_worker(0.5);
  // The delays are drawn below the shortest complete run seen so far: the
  // uninterrupted run at first, then any faulted run that ended before its
  // fault (on a shared machine the first run may have been the slow one).
  // A fault that missed is followed by another, up to 3 x kFaults rounds.
  double shortest = full_seconds_;
  int matrix_kills = 0, worker_kills = 0, missed = 0, reruns = 0, mismatches = 0;
  for (int round = 0; round < 3 * kFaults && matrix_kills + worker_kills < kFaults; ++round) {
    const bool worker = of_a_worker(rng);
    const double delay = std::uniform_real_distribution<double>(0.0, 0.95 * shortest)(rng);
    SCOPED_TRACE("seed " + std::to_string(seed_) + " (CSTAB_CRASH_SEED), fault " + std::to_string(round) +
                 ": kill -9 of " + (worker ? "a worker" : "the matrix") + " after " + std::to_string(delay) + " s of a " +
                 std::to_string(shortest) + " s run");
    const fs::path out = dir_->dir() / ("fault" + std::to_string(round));
    const auto start = Clock::now();
    const pid_t pid = spawn_matrix(toml(), out, out.string() + ".log");
    std::this_thread::sleep_until(start + std::chrono::duration<double>(delay));
    int code = exit_code_if_ended(pid);
    bool injected = false;
    if (!worker) {
      injected = code < 0 && ::kill(pid, SIGKILL) == 0;
    } else {
      // The first worker alive from then on (once a case folder exists:
      // before, a child may be a provenance helper between fork and exec).
      while (!injected && code < 0) {
        std::error_code ec;
        if (!fs::is_empty(out / "cases", ec) && !ec)
          for (pid_t w : workers_of(pid)) injected = injected || ::kill(w, SIGKILL) == 0;
        if (injected) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        code = exit_code_if_ended(pid);
      }
    }
    if (code < 0) code = wait_code(pid);
    // A matrix that had exited but was not yet reaped takes a kill without
    // dying of it: it ended on its own, so the fault missed.
    if (!worker && injected && code != 128 + SIGKILL) injected = false;
    if (!injected) shortest = std::min(shortest, std::chrono::duration<double>(Clock::now() - start).count());
    const std::string log = slurp(out.string() + ".log");
    if (!injected) {
      ++missed;  // the run had ended: it must simply be complete
      EXPECT_EQ(code, 0) << log;
    } else if (!worker) {
      ++matrix_kills;
      EXPECT_EQ(code, 128 + SIGKILL) << log;
      // Its workers die with it (PR_SET_PDEATHSIG); 0.5 s is far less than
      // the cases still running would need.
      const auto deadline = Clock::now() + std::chrono::milliseconds(500);
      while (processes_on(out) > 0 && Clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      EXPECT_EQ(processes_on(out), 0u) << "a worker outlived its matrix";
    } else {
      ++worker_kills;
      // Killed before its end, the worker's case is reported, not recorded,
      // and the matrix fails; a worker already exiting when hit may have
      // finished its case, and then the run is complete.
      if (code != 0) {
        EXPECT_EQ(code, 1) << log;
        EXPECT_NE(log.find("NOT RECORDED"), std::string::npos) << log;
      }
    }
    // Never success with a case missing or wrong; never a wrong row at all.
    if (code == 0) {
      EXPECT_EQ(summary_without_timing(out / "summary.csv"), expected()) << log;
    }
    if (fs::exists(out / "summary.csv")) {
      EXPECT_TRUE(rows_are_a_subset(out / "summary.csv", dir_->dir() / "full" / "summary.csv"))
          << slurp(out / "summary.csv");
    }
    // The rerun completes to the uninterrupted run's summary.
    mismatches += !rerun_and_compare(out);
    ++reruns;
  }
  std::cout << "crash-consistency: " << (matrix_kills + worker_kills) << " faults injected (" << matrix_kills
            << " of the matrix, " << worker_kills << " of a worker), " << missed << " after the run had ended; "
            << reruns << " reruns compared with the uninterrupted run, " << mismatches << " mismatches\n";
  EXPECT_EQ(mismatches, 0);
  // The faults are not all missed: at least half of them landed.
  EXPECT_GE(matrix_kills + worker_kills, kFaults / 2);
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
  // Each case's record (case.txt: key, series hash, summary rows) damaged
  // one way, or its series.
  fs::resize_file(folder(0) / "case.txt", fs::file_size(folder(0) / "case.txt") - 3);  // truncated
  {  // a number of the summary rows edited, the size kept
    std::string record = slurp(folder(1) / "case.txt");
    const size_t at = record.rfind("e-") - 1;
    ASSERT_GT(at, record.find("\nsummary ")) << record;
    record[at] = record[at] == '1' ? '2' : '1';
    std::ofstream(folder(1) / "case.txt", std::ios::binary) << record;
  }
  fs::resize_file(folder(2) / "series.csv.gz", 100);                             // series truncated
  fs::remove(folder(3) / "case.txt");                                           // deleted
  fs::rename(folder(4) / "case.txt", dir_->dir() / "c4.txt");                   // swapped
  fs::rename(folder(5) / "case.txt", folder(4) / "case.txt");
  fs::rename(dir_->dir() / "c4.txt", folder(5) / "case.txt");
  fs::remove(out / "summary.csv");
  const pid_t pid = spawn_matrix(toml(), out, out.string() + ".log");
  ASSERT_EQ(wait_code(pid), 0) << slurp(out.string() + ".log");
  const std::string log = slurp(out.string() + ".log");
  size_t reruns = 0;
  for (size_t p = log.find("matrix: rerun "); p != std::string::npos; p = log.find("matrix: rerun ", p + 1)) ++reruns;
  EXPECT_EQ(reruns, 6u) << log;
  // Each rerun says why.
  const std::pair<size_t, const char*> why[] = {
      {0, "case.txt: its summary rows have "},
      {1, "case.txt: its summary rows differ from the recorded hash (edited)"},
      {2, "series.csv.gz has 100 bytes"},
      {3, "no case.txt (unfinished)"},
      {4, "case.txt records another configuration (swapped or copied from another case, or edited)"},
      {5, "case.txt records another configuration (swapped or copied from another case, or edited)"}};
  for (const auto& [i, reason] : why)
    EXPECT_NE(log.find("(" + cases.get(i, "case_id") + "): " + reason), std::string::npos) << i << ": " << log;
  EXPECT_NE(log.find("6 run, 0 cached"), std::string::npos) << log;
  EXPECT_EQ(summary_without_timing(out / "summary.csv"), expected());
  EXPECT_EQ(unfinished_case_folders(out), std::vector<std::string>{});
}


// Disk full: a tmpfs three quarters the size of the results (the series of
// the two running cases, uncompressed, take most of it). The matrix exits 1 and
// names the I/O failure; nothing is cached because of it (no case recorded
// as failed, no half-written case folder, no temporary file); a rerun on
// the still-full disk fails the same way; once there is space (the tmpfs
// remounted bigger, its files kept), a rerun completes to the uninterrupted
// run's summary, reusing exactly the cases the full disk let finish.
TEST_F(CrashConsistency, DiskFullIsReportedNothingIsCachedForItAndTheRerunCompletesOnceThereIsSpace) {
  ASSERT_EQ(full_code_, 0) << slurp(dir_->dir() / "full.log");
  size_t full_bytes = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_->dir() / "full"))
    if (e.is_regular_file()) full_bytes += e.file_size();
  const size_t disk_bytes = full_bytes / 4 * 3;
  SmallDisk disk(dir_->dir() / "disk", disk_bytes);
  if (!disk.mounted()) GTEST_SKIP() << "cannot create a small disk to fill: " << disk.why_not();
  const fs::path out = dir_->dir() / "disk" / "R";
  size_t kept = 0;
  for (int attempt = 0; attempt < 2; ++attempt) {
    SCOPED_TRACE(attempt == 0 ? "the disk fills (" + std::to_string(disk_bytes) + " bytes for " +
                                    std::to_string(full_bytes) + " of results)"
                              : std::string("a rerun on the still-full disk"));
    const fs::path log_path = dir_->dir() / ("disk" + std::to_string(attempt) + ".log");
    const int code = wait_code(spawn_matrix(toml(), out, log_path));
    const std::string log = slurp(log_path);
    EXPECT_EQ(code, 1) << log;
    EXPECT_NE(log.find("NOT RECORDED"), std::string::npos) << log;
    EXPECT_TRUE(log.find("(disk full)") != std::string::npos ||
                log.find("No space left on device") != std::string::npos)
        << log;
    EXPECT_NE(log.find("not recorded (a worker crashed, was killed from outside or hit an I/O error"),
              std::string::npos)
        << log;
    // Only complete cases remain, and only right ones.
    EXPECT_EQ(unfinished_case_folders(out), std::vector<std::string>{});
    EXPECT_EQ(temporaries(out), 0u);
    kept = case_folders(out);
    EXPECT_LT(kept, 6u);
    if (fs::exists(out / "summary.csv")) {
      EXPECT_TRUE(rows_are_a_subset(out / "summary.csv", dir_->dir() / "full" / "summary.csv"))
          << slurp(out / "summary.csv");
    }
  }
  ASSERT_TRUE(disk.grow(64u << 20)) << std::strerror(errno);
  const fs::path log_path = dir_->dir() / "disk_freed.log";
  const int code = wait_code(spawn_matrix(toml(), out, log_path));
  const std::string log = slurp(log_path);
  EXPECT_EQ(code, 0) << log;
  EXPECT_EQ(summary_without_timing(out / "summary.csv"), expected());
  EXPECT_EQ(temporaries(out), 0u);
  EXPECT_NE(log.find(std::to_string(6 - kept) + " run, " + std::to_string(kept) + " cached"), std::string::npos)
      << log;
  std::cout << "disk full: " << disk_bytes << " bytes for " << full_bytes << " of results; " << kept
            << " of 6 cases completed on the full disk and were reused, " << 6 - kept << " run once there was space\n";
}

}  // namespace

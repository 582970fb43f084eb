// Running a matrix: a pool of forked workers, the per-case cache, progress,
// the manifest and summary of a results folder, and merging shard folders.
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "core/format.hpp"
#include "io/csv.hpp"
#include "io/gzip.hpp"
#include "io/hash.hpp"
#include "io/lock.hpp"
#include "io/number.hpp"
#include "matrix/external.hpp"
#include "matrix/matrix.hpp"
#include "matrix/provenance.hpp"
#include "matrix/results.hpp"
#include "methods/pair.hpp"
#include "plugin/loader.hpp"
#include "problems/registry.hpp"

namespace cstab {

namespace fs = std::filesystem;

namespace {

using Row = std::vector<std::pair<std::string, std::string>>;
using Clock = std::chrono::steady_clock;

// Child exit codes.
constexpr int kExitOk = 0, kExitDiverged = 10, kExitFailed = 11, kExitInvalid = 12, kExitOrphan = 13,
              kExitInfrastructure = 14;

std::string case_folder(const std::string& out, const std::string& id) { return out + "/cases/" + id; }

// A case of a plugin's method or problem is also keyed by the plugin's
// content: the same file gives cached results, a rebuilt one does not.
std::string cache_key(const MatrixCase& c, const std::string& binary_id) {
  std::string key = c.config_text + "binary=" + binary_id + "\n";
  const std::string method_plugin = origin_identity(method_origin(c.config.method));
  const std::string problem_plugin = origin_identity(problem_origin(c.config.problem));
  if (!method_plugin.empty()) key += "method_plugin=" + method_plugin + "\n";
  if (!problem_plugin.empty()) key += "problem_plugin=" + problem_plugin + "\n";
  return key;
}

bool file_equals(const std::string& path, const std::string& content) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  std::string data(content.size() + 1, '\0');
  const size_t n = std::fread(data.data(), 1, data.size(), f);
  std::fclose(f);
  return n == content.size() && data.compare(0, n, content) == 0;
}

// A row for a case that produced no RunResult (crash, timeout, bad input).
Row failure_row(const MatrixCase& c, Status status, const std::string& reason) {
  const RunConfig& cfg = c.config;
  Row row;
  row.emplace_back("case_id", c.entry.id);
  row.emplace_back("repeat", "0");
  row.emplace_back("problem", cfg.problem);
  row.emplace_back("problem_params", c.entry.problem_params);
  row.emplace_back("formulation", cfg.formulation);
  row.emplace_back("method", cfg.method);
  row.emplace_back("params", c.entry.params);
  row.emplace_back("integrator", cfg.integrator);
  row.emplace_back("step", cfg.step.step > 0 ? format_short(cfg.step.step) : "");
  row.emplace_back("rtol", cfg.step.rtol > 0 ? format_short(cfg.step.rtol) : "");
  row.emplace_back("atol", cfg.step.atol > 0 ? format_short(cfg.step.atol) : "");
  row.emplace_back("status", status_name(status));
  row.emplace_back("reason", reason);
  row.emplace_back("t_end", format_short(cfg.t_end));
  return row;
}

// The files beside case.txt whose content it records (`file` lines).
// series.csv.gz is what the worker keeps of the harness's series.csv;
// series.csv stays listed for folders of older cstab versions.
constexpr const char* kResultFiles[] = {"series.csv", "series.csv.gz"};

// The harness's series.csv as series.csv.gz (lossless, about 3x smaller):
// the gzip file is written atomically before the plain one goes.
void compress_series(const std::string& dir) {
  const std::string plain = dir + "/series.csv";
  if (!fs::exists(plain)) return;
  write_file_atomic(plain + ".gz", gzip_compress(read_text_file(plain)));
  fs::remove(plain);
}

// "file NAME SIZE HASH" lines for the result files present in `dir`: a
// 64-bit FNV-1a of the content (io/hash.hpp). It guards against accidents
// (a truncated, edited, swapped or half-copied file), not against an
// attacker, who could forge a matching file.
std::string content_lines(const std::string& dir) {
  std::string out;
  for (const char* name : kResultFiles) {
    const std::string path = dir + "/" + name;
    if (!fs::exists(path)) continue;
    const std::string bytes = read_text_file(path);
    out += std::string("file ") + name + " " + std::to_string(bytes.size()) + " " + hash_hex(bytes) + "\n";
  }
  return out;
}

// The case's record, case.txt: the key, the result files' lines and the
// summary rows in one file, written last (it marks the result complete).
// The harness's summary.csv of the first repeat goes first: its row is in
// `rows`, and a case folder holds no file its record does not account for.
void write_result(const std::string& dir, const std::vector<Row>& rows, const std::string& key) {
  std::error_code ec;
  fs::remove(dir + "/summary.csv", ec);
  if (ec) throw std::runtime_error(dir + "/summary.csv: cannot remove: " + ec.message());
  write_file_atomic(dir + "/" + kCaseRecordName, case_record_text(key + content_lines(dir), rows_to_csv(rows)));
}

// Why the cached result of `c` in `dir` cannot be reused with this binary
// ("" if it can): case.txt must be whole (its summary rows of the size and
// hash it records), begin with this configuration and binary, and list
// every result file beside it with the size and hash it has now. A series
// dropped or cut by an earlier run (`dropped NAME`, `for-pictures NAME`:
// shrink_series) is fine unless `need_series`.
std::string cache_problem(const std::string& dir, const MatrixCase& c, const std::string& binary_id,
                          bool need_series) {
  const std::string key = cache_key(c, binary_id);
  std::string text;
  try {
    text = read_text_file(dir + "/" + kCaseRecordName);
  } catch (const std::exception&) {
    if (fs::exists(dir + "/key.txt")) return "written by an older cstab (key.txt and summary.csv, no case.txt)";
    return fs::exists(dir) ? "no case.txt (unfinished)" : "not run yet";
  }
  std::string why;
  const auto record = parse_case_record(text, why);
  if (!record) return why;
  if (record->head.compare(0, key.size(), key) != 0) {
    // The folder's name is the hash of its configuration: a record of
    // another configuration was swapped, copied or edited in.
    if (record->head.compare(0, c.config_text.size(), c.config_text) != 0)
      return std::string(kCaseRecordName) +
             " records another configuration (swapped or copied from another case, or edited)";
    return "configuration or binary changed";
  }
  std::istringstream lines(record->head.substr(key.size()));
  std::string line;
  std::set<std::string> listed;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string tag, name, hash;
    unsigned long long size = 0;
    if (line.rfind("dropped ", 0) == 0 || line.rfind("for-pictures ", 0) == 0) {
      if (need_series)
        return line[0] == 'd' ? "its series was dropped by an earlier run (keep_series asks for it)"
                              : "its series was cut to the pictures' columns and 7 digits by an earlier run "
                                "(keep_series asks for the whole one)";
      continue;
    }
    if (!(words >> tag >> name >> size >> hash) || tag != "file")
      return std::string(kCaseRecordName) + ": malformed line '" + line + "'";
    listed.insert(name);
    const std::string path = dir + "/" + name;
    std::error_code ec;
    const auto actual = fs::file_size(path, ec);
    if (ec) return name + " missing";
    if (actual != size)
      return name + " has " + std::to_string(actual) + " bytes, " + std::to_string(size) + " recorded (truncated or edited)";
    std::string bytes;
    try {
      bytes = read_text_file(path);
    } catch (const std::exception&) {
      return name + " unreadable";
    }
    if (hash_hex(bytes) != hash) return name + " content differs from the recorded hash (edited or swapped)";
  }
  for (const char* name : {"series.csv", "series.csv.gz", "summary.csv"})
    if (!listed.count(name) && fs::exists(dir + "/" + name))
      return std::string(name) + " not recorded in " + kCaseRecordName;
  return "";
}

// In the forked worker: every repeat of one case. Returns the exit code.
int run_in_worker(const MatrixCase& c, const Problem& problem, const std::string& dir, const std::string& key) {
  std::vector<Row> rows;
  int code = kExitOk;
  const Clock::time_point start = Clock::now();
  for (int r = 0; r < c.entry.repeats; ++r) {
    RunConfig cfg = c.config;
    cfg.write_series = cfg.write_series && r == 0;
    RunResult result;
    try {
      if (c.external.empty()) {
        result = run_case(problem, cfg, r == 0 ? dir : std::string());
      } else {
        // The program's own deadline, before the pool's timeout kills this worker.
        const double left = c.timeout > 0 ? 0.9 * c.timeout - std::chrono::duration<double>(Clock::now() - start).count()
                                          : 0.0;
        ExternalOutcome o = run_external(c, problem, dir, r == 0 ? dir : std::string(), c.timeout > 0 ? std::max(left, 1e-3) : 0.0);
        if (o.status != Status::kOk) {
          rows = {failure_row(c, o.status, o.reason)};
          code = kExitFailed;
          break;
        }
        result = std::move(o.result);
      }
    } catch (const UsageError& e) {
      rows = {failure_row(c, Status::kInvalid, e.what())};
      code = kExitInvalid;
      break;
    } catch (const IoError&) {
      throw;  // the machine's failure, not the case's: never recorded as a result
    } catch (const std::exception& e) {
      rows = {failure_row(c, Status::kFailed, std::string("exception: ") + e.what())};
      code = kExitFailed;
      break;
    }
    Row row = result.summary_row();
    row.insert(row.begin(), {{"case_id", c.entry.id}, {"repeat", std::to_string(r)}});
    rows.push_back(std::move(row));
    const Status status = status_from_cell(result.status);
    if (status != Status::kOk) {  // repeats only time successful runs
      code = status == Status::kDiverged ? kExitDiverged : kExitFailed;
      break;
    }
    // A long run is timed well enough once.
    if (c.repeat_if_under > 0 && result.wall_seconds >= c.repeat_if_under) break;
  }
  compress_series(dir);
  write_result(dir, rows, key);
  return code;
}

// h:mm:ss or m:ss; "?" when unknown or past 100 hours (an ETA from a first
// case that cost next to nothing: converting it to long would overflow).
std::string clock_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0 || seconds >= 360000) return "?";
  const long s = long(seconds + 0.5);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

struct Running {
  const MatrixCase* c;
  Clock::time_point start;
};

// ---- interruption ----
// The signal that asked the matrix to stop (0: none). Set by the handler only.
volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_stop_signal(int sig) {
  if (!g_stop_signal) g_stop_signal = sig;
}
constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

// A worker killed by one of these was interrupted, not crashed.
bool is_stop_signal(int sig) { return sig == SIGINT || sig == SIGTERM || sig == SIGHUP; }

// While alive, SIGINT/SIGTERM/SIGHUP set g_stop_signal instead of killing
// the process; the previous dispositions come back afterwards. A signal
// ignored on entry (a background job of a non-interactive shell, nohup)
// stays ignored, here and in the workers.
bool g_ignored[std::size(kStopSignals)];

class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    for (size_t i = 0; i < std::size(kStopSignals); ++i) {
      ::sigaction(kStopSignals[i], nullptr, &old_[i]);
      g_ignored[i] = old_[i].sa_handler == SIG_IGN;
      if (!g_ignored[i]) ::sigaction(kStopSignals[i], &sa, nullptr);
    }
  }
  ~StopSignals() {
    for (size_t i = 0; i < std::size(kStopSignals); ++i) ::sigaction(kStopSignals[i], &old_[i], nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // Blocks the stop signals (around fork(), so a child never runs the
  // parent's handler), and unblocks them.
  static void block(bool on) {
    sigset_t set;
    sigemptyset(&set);
    for (int sig : kStopSignals) sigaddset(&set, sig);
    ::sigprocmask(on ? SIG_BLOCK : SIG_UNBLOCK, &set, nullptr);
  }
  // In a worker: the default actions, so a stop signal ends it at once.
  static void defaults_in_child() {
    for (size_t i = 0; i < std::size(kStopSignals); ++i) ::signal(kStopSignals[i], g_ignored[i] ? SIG_IGN : SIG_DFL);
    block(false);
  }

 private:
  struct sigaction old_[std::size(kStopSignals)];
};

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

}  // namespace

std::string stop_signal_name(int sig) { return signal_name(sig); }

namespace {

// The folder's cases.csv and matrix.toml, written before anything runs.
void prepare_folder(const std::vector<MatrixCase>& cases, const MatrixRunOptions& opt) {
  std::error_code ec;
  fs::create_directories(opt.out_dir + "/cases", ec);
  if (ec) throw UsageError("--out " + opt.out_dir + ": cannot create folder: " + ec.message());
  std::vector<CaseEntry> entries;
  for (const auto& c : cases) entries.push_back(c.entry);
  write_manifest(opt.out_dir + "/cases.csv", entries, opt.selected_cases);
  write_file_atomic(opt.out_dir + "/matrix.toml", opt.matrix_text);
}

// The cases without a cached result (same configuration and binary), longest first.
std::vector<const MatrixCase*> uncached_cases(const std::vector<MatrixCase>& cases, const MatrixRunOptions& opt,
                                              MatrixRunStats& stats, std::ostream& log) {
  std::vector<const MatrixCase*> todo;
  for (const auto& c : cases) {
    const std::string dir = case_folder(opt.out_dir, c.entry.id);
    if (!opt.force && !opt.binary_id.empty() && opt.binary_id != "unknown") {
      const std::string why = cache_problem(dir, c, opt.binary_id, c.keep_series && c.config.write_series);
      if (why.empty()) {
        ++stats.cached;
        continue;
      }
      // A result that was there but cannot be trusted: say why it runs again.
      if (why != "not run yet" && why != "configuration or binary changed")
        log << "matrix: rerun " << c.entry.label() << "  (" << c.entry.id << "): " << why << "\n";
    }
    todo.push_back(&c);
  }
  if (stats.cached)
    log << "matrix: " << stats.cached << " of " << stats.total
        << " cases cached (same configuration and binary, result in " << opt.out_dir << "/cases): not rerun\n";
  // Longest first, so the pool does not end waiting on one long case.
  std::stable_sort(todo.begin(), todo.end(),
                   [](const MatrixCase* a, const MatrixCase* b) { return a->cost_estimate > b->cost_estimate; });
  return todo;
}

// Reference solutions: computed once here, inherited by every worker.
void compute_references(const std::vector<const MatrixCase*>& todo, const MatrixRunOptions& opt) {
  std::set<std::pair<std::string, double>> done;
  for (const MatrixCase* c : todo) {
    if (g_stop_signal) break;
    const Problem& p = opt.find_problem(c->config.problem);
    const double t = c->config.ref_time < 0 ? p.info().reference_time : c->config.ref_time;
    // A problem variant (problem_params) computes its own reference in the worker.
    if (!c->config.problem_params.empty()) continue;
    if (!(t > 0) || t > c->config.t_end || !done.insert({c->config.problem, t}).second) continue;
    std::vector<double> buf(p.info().coordinates.size());
    p.reference(t, buf.data());
  }
}

// The status of a finished worker and why (for the ones without a RunResult).
std::pair<Status, std::string> worker_outcome(const MatrixCase& c, int wait_status, bool timed_out) {
  if (timed_out) return {Status::kTimeout, "killed after " + format_short(c.timeout) + " s (timeout)"};
  if (WIFEXITED(wait_status)) {
    switch (WEXITSTATUS(wait_status)) {
      case kExitOk: return {Status::kOk, ""};
      case kExitDiverged: return {Status::kDiverged, ""};
      case kExitFailed: return {Status::kFailed, ""};
      case kExitInvalid: return {Status::kInvalid, ""};
      default: return {Status::kCrashed, "worker exited with code " + std::to_string(WEXITSTATUS(wait_status))};
    }
  }
  return {Status::kCrashed, std::string("worker killed by signal ") + std::to_string(WTERMSIG(wait_status)) + " (" +
                                strsignal(WTERMSIG(wait_status)) + ")"};
}

// The pool of workers over the uncached cases: starts, reaps, times out, stops.
class WorkerPool {
 public:
  WorkerPool(std::vector<const MatrixCase*> todo, const MatrixRunOptions& opt, MatrixRunStats& stats,
             std::ostream& log, bool tty, Clock::time_point start)
      : todo_(std::move(todo)), opt_(opt), stats_(stats), log_(log), tty_(tty), start_(start) {
    for (const MatrixCase* c : todo_) cost_total_ += c->cost_estimate;
  }

  // Until every case ran or a stop signal came.
  void run() {
    const size_t jobs = size_t(std::max(1, opt_.jobs));
    while (!g_stop_signal && (next_ < todo_.size() || !running_.empty())) {
      while (!g_stop_signal && running_.size() < jobs && next_ < todo_.size()) start_worker(*todo_[next_++]);
      if (reap_one()) continue;
      kill_timed_out();
      draw(false);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  // After a stop signal: SIGTERM to the running workers, SIGKILL after a grace period.
  void stop();

  // The final progress line.
  void finish() {
    if (tty_) log_ << "\r\033[K" << progress_line() << "\n";
  }

 private:
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  std::string eta_text() const {
    return finished_ == todo_.size() ? "0:00" : clock_text(elapsed() * (cost_total_ - cost_done_) / cost_done_);
  }
  std::string progress_line() const;
  void draw(bool force);
  void start_worker(const MatrixCase& c);
  bool reap_one();
  void kill_timed_out();
  void unfinished(const MatrixCase& c, const std::string& why);
  void record(const MatrixCase& c, int wait_status, double seconds, bool timed_out);
  void report_line(const MatrixCase& c, Status outcome, const std::string& reason, double seconds, bool failure);

  std::vector<const MatrixCase*> todo_;
  const MatrixRunOptions& opt_;
  MatrixRunStats& stats_;
  std::ostream& log_;
  const bool tty_;
  const Clock::time_point start_;
  std::map<pid_t, Running> running_;
  size_t next_ = 0, finished_ = 0;
  double cost_total_ = 0, cost_done_ = 0;
  Clock::time_point last_draw_ = Clock::now() - std::chrono::seconds(1);
};

std::string WorkerPool::progress_line() const {
  const double t = elapsed();
  const double eta = cost_done_ > 0 ? t * (cost_total_ - cost_done_) / cost_done_ : NAN;
  std::ostringstream s;
  s << "[" << (stats_.cached + finished_) << "/" << stats_.total << "] " << clock_text(t) << " elapsed, ETA "
    << (finished_ == todo_.size() ? "0:00" : clock_text(eta)) << ", " << stats_.failed << " failed, "
    << stats_.diverged << " diverged, " << stats_.not_applicable << " n/a, " << stats_.cached << " cached, "
    << running_.size() << " running";
  return s.str();
}

void WorkerPool::draw(bool force) {
  if (!tty_) return;
  if (!force && Clock::now() - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = Clock::now();
  log_ << "\r\033[K" << progress_line() << std::flush;
}

// Forks a worker for `c` in a fresh case folder.
void WorkerPool::start_worker(const MatrixCase& c) {
  std::error_code ec;
  const std::string dir = case_folder(opt_.out_dir, c.entry.id);
  fs::remove_all(dir, ec);  // nothing stale survives: incomplete until the worker writes case.txt
  fs::create_directories(dir, ec);
  const std::string key = cache_key(c, opt_.binary_id);
  const Problem& problem = opt_.find_problem(c.config.problem);
  log_.flush();
  std::fflush(nullptr);
  StopSignals::block(true);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // A worker dies with its parent (a matrix killed with -9 leaves no
    // orphan computing on); if the parent died before prctl, exit now.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(kExitOrphan);
    StopSignals::defaults_in_child();
    // The worker's own bound, should the parent be too busy to kill it:
    // SIGALRM a few seconds after the case's timeout.
    if (c.timeout > 0) ::alarm(unsigned(std::min(c.timeout + 5.0, 1e9)));
    int code = kExitFailed;
    try {
      code = run_in_worker(c, problem, dir, key);
    } catch (const std::exception& e) {
      // An I/O error (disk full, ...) or an unexpected exception: the
      // parent reports it and records nothing.
      std::fprintf(stderr, "cstab matrix: worker for case %s: %s\n", c.entry.id.c_str(), e.what());
      code = kExitInfrastructure;
    } catch (...) {
      code = kExitInfrastructure;
    }
    std::fflush(nullptr);
    ::_exit(code);
  }
  StopSignals::block(false);
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  running_[pid] = {&c, Clock::now()};
  draw(false);
}

// Records a worker that exited, if one did; false if none had.
bool WorkerPool::reap_one() {
  int status = 0;
  const pid_t pid = ::waitpid(-1, &status, WNOHANG);
  if (pid <= 0) return false;
  auto it = running_.find(pid);
  if (it == running_.end()) return true;  // not ours
  const Running r = it->second;
  running_.erase(it);
  record(*r.c, status, std::chrono::duration<double>(Clock::now() - r.start).count(), false);
  return true;
}

// Kills and records the workers past their case's timeout.
void WorkerPool::kill_timed_out() {
  for (auto it = running_.begin(); it != running_.end();) {
    const double age = std::chrono::duration<double>(Clock::now() - it->second.start).count();
    if (it->second.c->timeout > 0 && age > it->second.c->timeout) {
      int status = 0;
      ::kill(it->first, SIGKILL);
      ::waitpid(it->first, &status, 0);
      const Running r = it->second;
      it = running_.erase(it);
      record(*r.c, status, age, true);
    } else {
      ++it;
    }
  }
}

// A worker that did not finish (stopped by a signal): no result, its
// partial folder removed, run again next time.
void WorkerPool::unfinished(const MatrixCase& c, const std::string& why) {
  std::error_code ec;
  fs::remove_all(case_folder(opt_.out_dir, c.entry.id), ec);
  ++stats_.unfinished;
  ++finished_;
  if (tty_) log_ << "\r\033[K";
  log_ << "[" << (stats_.cached + finished_) << "/" << stats_.total << "] unfinished " << c.entry.label() << "  ("
       << c.entry.id << ")\n    " << why << ": not recorded, runs again next time\n" << std::flush;
}

// A finished worker: its result recorded (written here for crashes and timeouts), counted, printed.
void WorkerPool::record(const MatrixCase& c, int wait_status, double seconds, bool timed_out) {
  // The worker's own alarm (matrix_run: start_worker) is its timeout.
  if (WIFSIGNALED(wait_status) && WTERMSIG(wait_status) == SIGALRM && c.timeout > 0) timed_out = true;
  const std::string dir = case_folder(opt_.out_dir, c.entry.id);
  auto [outcome, reason] = worker_outcome(c, wait_status, timed_out);
  if (!timed_out && WIFSIGNALED(wait_status) && is_stop_signal(WTERMSIG(wait_status))) {
    // Stopped after its whole record was written (a Ctrl-C to the process
    // group reaches a worker between case.txt and its exit): finished, kept.
    const CaseResult done = cache_problem(dir, c, opt_.binary_id, c.keep_series && c.config.write_series).empty()
                                ? load_case_result(opt_.out_dir, c.entry)
                                : CaseResult{};
    if (!done.complete || done.status == Status::kCrashed || done.status == Status::kTimeout) {
      unfinished(c, std::string("worker stopped by ") + signal_name(WTERMSIG(wait_status)));
      return;
    }
    outcome = done.status;
    reason.clear();
  }
  // Only simulation outcomes are cached (ok, diverged, failed, invalid,
  // timeout). A worker that crashed, was killed from outside or hit an I/O
  // error says nothing about the case: reported, not recorded, and the
  // matrix exits non-zero.
  if (outcome == Status::kCrashed) {
    std::error_code ec;
    fs::remove_all(dir, ec);
    ++stats_.infrastructure;
    ++finished_;
    if (tty_) log_ << "\r\033[K";
    log_ << "[" << (stats_.cached + finished_) << "/" << stats_.total << "] NOT RECORDED " << c.entry.label() << "  ("
         << c.entry.id << ")\n    "
         << (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == kExitInfrastructure
                 ? std::string("infrastructure failure in the worker (message above)")
                 : reason)
         << ": not cached, runs again next time\n" << std::flush;
    return;
  }
  if (outcome == Status::kTimeout) {
    try {
      // Nothing the killed worker left half-written (its *.tmp.<pid> files,
      // a series.csv of an earlier repeat) stays beside the recorded outcome.
      std::error_code ec;
      fs::remove_all(dir, ec);
      fs::create_directories(dir, ec);
      write_result(dir, {failure_row(c, outcome, reason)}, cache_key(c, opt_.binary_id));
    } catch (const std::exception& e) {
      std::error_code ec;
      fs::remove_all(dir, ec);
      ++stats_.infrastructure;
      ++finished_;
      log_ << "[" << (stats_.cached + finished_) << "/" << stats_.total << "] NOT RECORDED " << c.entry.label()
           << "  (" << c.entry.id << ")\n    cannot record its " << status_name(outcome) << ": " << e.what() << "\n"
           << std::flush;
      return;
    }
  }
  const bool failure = outcome != Status::kOk && outcome != Status::kDiverged && outcome != Status::kInvalid;
  if (outcome == Status::kDiverged) ++stats_.diverged;
  if (outcome == Status::kInvalid) ++stats_.not_applicable;
  if (failure) ++stats_.failed;
  if (outcome != Status::kOk && outcome != Status::kDiverged && reason.empty()) {
    const CaseResult result = load_case_result(opt_.out_dir, c.entry);
    if (result.complete) reason = result.reason;
  }
  ++stats_.run;
  ++finished_;
  cost_done_ += c.cost_estimate;
  report_line(c, outcome, reason, seconds, failure);
}

// "[k/N elapsed, ETA] status seconds label (id)" and the reason of a failure.
void WorkerPool::report_line(const MatrixCase& c, Status outcome, const std::string& reason, double seconds,
                             bool failure) {
  std::ostringstream line;
  char head[96];
  std::snprintf(head, sizeof head, "[%zu/%zu %s, ETA %s] %-8s %7.2fs  ", stats_.cached + finished_, stats_.total,
                clock_text(elapsed()).c_str(), eta_text().c_str(),
                outcome == Status::kInvalid ? "n/a" : status_name(outcome), seconds);
  line << head << c.entry.label() << "  (" << c.entry.id << ")";
  if (!reason.empty() && outcome != Status::kOk && outcome != Status::kDiverged) line << "\n    " << reason;
  if (tty_) {
    if (failure) log_ << "\r\033[K" << line.str() << "\n";
    draw(true);
  } else {
    log_ << line.str() << "\n" << std::flush;
  }
}

// Stop: nothing new starts; running workers get SIGTERM, SIGKILL after
// a grace period. One that still exits on its own has finished (its
// case.txt is written) and is recorded; the others leave no folder.
void WorkerPool::stop() {
  stats_.interrupted_by = g_stop_signal;
  if (tty_) log_ << "\r\033[K";
  log_ << "matrix: " << signal_name(stats_.interrupted_by) << " received: stopping " << running_.size()
       << " running cases; " << (todo_.size() - next_) << " not started\n" << std::flush;
  for (const auto& [pid, r] : running_) ::kill(pid, SIGTERM);
  const auto deadline = Clock::now() + std::chrono::seconds(3);
  while (!running_.empty()) {
    if (reap_one()) continue;
    if (Clock::now() > deadline) {
      for (auto it = running_.begin(); it != running_.end(); it = running_.erase(it)) {
        int status = 0;
        ::kill(it->first, SIGKILL);
        ::waitpid(it->first, &status, 0);
        unfinished(*it->second.c, "worker did not stop within 3 s of SIGTERM: killed");
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  stats_.unfinished += todo_.size() - next_;
}

}  // namespace

MatrixRunStats run_matrix(const std::vector<MatrixCase>& cases, const MatrixRunOptions& opt, std::ostream& log,
                          bool tty) {
  const auto start = Clock::now();
  MatrixRunStats stats;
  stats.total = cases.size();
  const StopSignals stop_signals;
  // The manifest and the matrix first.
  prepare_folder(cases, opt);
  // What is cached is not rerun.
  std::vector<const MatrixCase*> todo = uncached_cases(cases, opt, stats, log);
  if (todo.empty()) {
    stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return stats;
  }
  // References once, before the fork.
  compute_references(todo, opt);
  // The pool, until done or stopped.
  WorkerPool pool(std::move(todo), opt, stats, log, tty, start);
  pool.run();
  if (g_stop_signal) pool.stop();
  stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  pool.finish();
  return stats;
}

// ---------------------------------------------------------------------------

void write_manifest(const std::string& path, const std::vector<CaseEntry>& entries, size_t selected_cases) {
  std::vector<Row> rows;
  for (const auto& e : entries) {
    rows.push_back({{"index", std::to_string(e.index)},
                    {"case_id", e.id},
                    {"sweep", e.sweep},
                    {"problem", e.problem},
                    {"problem_params", e.problem_params},
                    {"method", e.method},
                    {"formulation", e.formulation},
                    {"integrator", e.integrator},
                    {"params", e.params},
                    {"setting", e.setting},
                    {"t_end", format_exact(e.t_end)},
                    {"repeats", std::to_string(e.repeats)},
                    {"work_precision", e.work_precision ? "1" : "0"},
                    {"overlay", e.overlay ? "1" : "0"},
                    {"curve", e.curve},
                    {"selected_cases", std::to_string(selected_cases)}});
  }
  if (rows.empty())
    write_file_atomic(path,
                      "index,case_id,sweep,problem,problem_params,method,formulation,integrator,params,setting,t_end,"
                      "repeats,"
                      "work_precision,overlay,curve,selected_cases\n");
  else
    write_file_atomic(path, rows_to_csv(rows));
}

std::vector<CaseEntry> read_results_manifest(const std::string& dir) {
  std::vector<CaseEntry> entries;
  try {
    entries = read_manifest(dir + "/cases.csv");
  } catch (const UsageError&) {
    throw;  // a malformed manifest: its message names file:line:column
  } catch (const std::runtime_error& e) {
    throw UsageError(dir + ": not a matrix results folder (" + e.what() + ")");
  }
  std::sort(entries.begin(), entries.end(), [](const CaseEntry& a, const CaseEntry& b) { return a.index < b.index; });
  return entries;
}

std::vector<CaseEntry> read_manifest(const std::string& path, size_t* selected_cases) {
  const CsvTable t = read_csv(path);
  for (const char* col : {"index", "case_id", "problem", "method", "integrator", "curve"})
    if (t.column(col) < 0) throw UsageError(path + ": not a cstab case manifest (no column '" + col + "')");
  std::vector<CaseEntry> out;
  if (selected_cases) *selected_cases = 0;
  for (size_t i = 0; i < t.rows.size(); ++i) {
    // A number cell (io/number.hpp); `whole`: a non-negative integer.
    auto number = [&](const char* col, bool whole) {
      double v = 0;
      const std::string& text = t.get(i, col);
      if (!try_parse_number(text, v) || !std::isfinite(v) || (whole && (v < 0 || v != std::floor(v) || v > 1e15)))
        throw UsageError(t.where(i, col) + ": " + col + ": '" + text + "' is not " +
                         (whole ? "a count" : "a number"));
      return v;
    };
    CaseEntry e;
    e.index = size_t(number("index", true));
    e.id = t.get(i, "case_id");
    // An id names a folder: 16 hex digits and nothing else (no path).
    if (e.id.size() != 16 || e.id.find_first_not_of("0123456789abcdef") != std::string::npos)
      throw UsageError(t.where(i, "case_id") + ": case_id: '" + e.id + "' is not a case id (16 hex digits)");
    e.sweep = t.get(i, "sweep");
    e.problem = t.get(i, "problem");
    e.problem_params = t.get(i, "problem_params");  // absent in folders written before problem parameters
    e.method = t.get(i, "method");
    e.formulation = t.get(i, "formulation");
    e.integrator = t.get(i, "integrator");
    e.params = t.get(i, "params");
    e.setting = t.get(i, "setting");
    e.t_end = number("t_end", false);
    e.repeats = int(number("repeats", true));
    e.work_precision = t.get(i, "work_precision") == "1";
    e.overlay = t.get(i, "overlay") == "1";
    e.curve = t.get(i, "curve");
    if (selected_cases && !t.get(i, "selected_cases").empty()) *selected_cases = size_t(number("selected_cases", true));
    out.push_back(std::move(e));
  }
  return out;
}

size_t write_matrix_summary(const std::string& dir, const std::vector<CaseEntry>& entries) {
  std::vector<Row> rows;
  size_t missing = 0;
  for (const auto& e : entries) {
    const CaseResult c = load_case_result(dir, e);
    if (!c.complete) {
      ++missing;
      continue;
    }
    for (const auto& cells : c.rows) {  // the case's rows as written, with the sweep after "repeat"
      Row row;
      for (size_t i = 0; i < c.columns.size(); ++i) {
        row.emplace_back(c.columns[i], i < cells.size() ? cells[i] : "");
        if (c.columns[i] == "repeat") row.emplace_back("sweep", e.sweep);
      }
      rows.push_back(std::move(row));
    }
  }
  if (rows.empty())
    write_file_atomic(dir + "/summary.csv", "case_id,repeat,sweep\n");
  else
    write_file_atomic(dir + "/summary.csv", rows_to_csv(rows));
  return missing;
}

namespace {

// What the shard folders of a merge hold together.
struct Shards {
  std::string matrix_text;
  std::map<size_t, std::pair<CaseEntry, std::string>> by_index;  // index -> entry, source folder
  size_t selected_cases = 0;
  std::set<std::string> binaries;
  Provenance provenance;  // every shard's, keys prefixed "shard<k>."
  std::vector<std::unique_ptr<FolderLock>> locks;  // reading locks: no matrix writes a shard meanwhile
};

// Adds shard `s` (folder `dir`): same matrix as the first, consistent case ids.
void read_shard(Shards& shards, const std::string& out_dir, const std::vector<std::string>& shard_dirs, size_t s) {
  const std::string& dir = shard_dirs[s];
  std::error_code same_ec;
  if (fs::equivalent(dir, out_dir, same_ec)) throw UsageError("the output folder " + out_dir + " is also a shard folder");
  // A shard a matrix is still writing is refused (naming it), and none
  // starts on it until the merge is done.
  shards.locks.push_back(std::make_unique<FolderLock>(dir, "cstab merge", FolderLock::Mode::kRead));
  std::string text;
  try {
    text = read_text_file(dir + "/matrix.toml");
  } catch (const std::exception&) {
    throw UsageError(dir + " is not a matrix results folder (no matrix.toml)");
  }
  if (s == 0)
    shards.matrix_text = text;
  else if (text != shards.matrix_text)
    throw UsageError(dir + " ran a different matrix than " + shard_dirs[0] + " (matrix.toml differs)");
  size_t n = 0;
  std::vector<CaseEntry> entries;
  try {
    entries = read_manifest(dir + "/cases.csv", &n);
  } catch (const UsageError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw UsageError(dir + ": " + e.what());
  }
  if (n) shards.selected_cases = n;
  for (auto& e : entries) {
    auto [it, inserted] = shards.by_index.emplace(e.index, std::make_pair(e, dir));
    if (!inserted && it->second.first.id != e.id)
      throw UsageError("case " + std::to_string(e.index) + " differs between " + it->second.second + " and " + dir);
  }
  try {
    for (auto [k, v] : parse_provenance(read_text_file(dir + "/provenance.txt"))) {
      if (k == "binary_identity") shards.binaries.insert(v);
      shards.provenance.emplace_back("shard" + std::to_string(s + 1) + "." + k, v);
    }
  } catch (const std::exception&) {
  }
}

// Copies every complete case folder not already in out_dir (case.txt
// last, into a folder emptied first); returns how many.
size_t copy_complete_cases(const std::string& out_dir, const Shards& shards, std::vector<CaseEntry>& entries) {
  std::error_code ec;
  size_t copied = 0;
  for (const auto& [index, entry_source] : shards.by_index) {
    const auto& [e, source] = entry_source;
    entries.push_back(e);
    if (!load_case_result(source, e).complete) continue;  // counted by write_matrix_summary
    const std::string from = case_folder(source, e.id), to = case_folder(out_dir, e.id);
    const std::string record = read_text_file(from + "/" + kCaseRecordName);
    if (file_equals(to + "/" + kCaseRecordName, record)) continue;
    fs::remove_all(to, ec);
    fs::create_directories(to, ec);
    for (const auto& f : fs::directory_iterator(from)) {
      if (f.path().filename() == kCaseRecordName || !f.is_regular_file()) continue;
      fs::copy_file(f.path(), to + "/" + f.path().filename().string(), fs::copy_options::overwrite_existing);
    }
    write_file_atomic(to + "/" + kCaseRecordName, record);
    ++copied;
  }
  return copied;
}

}  // namespace

size_t merge_results(const std::string& out_dir, const std::vector<std::string>& shard_dirs, std::ostream& log) {
  if (shard_dirs.empty()) throw UsageError("give at least one shard folder");
  // Read and check every shard.
  Shards shards;
  for (size_t s = 0; s < shard_dirs.size(); ++s) read_shard(shards, out_dir, shard_dirs, s);
  if (shards.binaries.size() > 1)
    log << "merge: warning: the shards were run by " << shards.binaries.size() << " different binaries\n";
  // Copy the complete cases, with OUT locked.
  const std::unique_ptr<FolderLock> lock = create_locked_folder(out_dir, "cstab merge", "cannot create " + out_dir);
  std::error_code ec;
  fs::create_directories(out_dir + "/cases", ec);
  if (ec) throw UsageError("cannot create " + out_dir + ": " + ec.message());
  std::vector<CaseEntry> entries;
  const size_t copied = copy_complete_cases(out_dir, shards, entries);
  // The union manifest, the matrix, provenance of every shard, summary.csv.
  write_file_atomic(out_dir + "/matrix.toml", shards.matrix_text);
  write_manifest(out_dir + "/cases.csv", entries, shards.selected_cases);
  Provenance own = collect_provenance();
  own.emplace_back("merged_from", std::to_string(shard_dirs.size()) + " shard folders");
  own.insert(own.end(), shards.provenance.begin(), shards.provenance.end());
  write_file_atomic(out_dir + "/provenance.txt", format_provenance(own));
  const size_t missing_results = write_matrix_summary(out_dir, entries);
  const size_t uncovered = shards.selected_cases > entries.size() ? shards.selected_cases - entries.size() : 0;
  log << "merge: " << entries.size() << " cases from " << shard_dirs.size() << " folders (" << copied
      << " copied) into " << out_dir << "\n";
  if (missing_results) log << "merge: warning: " << missing_results << " cases have no complete result\n";
  return uncovered + missing_results;
}

namespace {

// The record (case.txt) of `dir`, split at its `summary` line; nullopt if
// it is unreadable or not whole (unfinished or damaged: the cache check
// deals with it).
std::optional<CaseRecord> read_record(const std::string& dir) {
  try {
    std::string why;
    return parse_case_record(read_text_file(dir + "/" + kCaseRecordName), why);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// The text of the record of `dir` with its `file NAME ...` line replaced
// by `lines`; "" if the record is unreadable or not whole (the next run
// redoes the case) or does not record NAME (left for the cache check to
// refuse).
std::string record_with(const std::string& dir, const std::string& name, const std::string& lines) {
  auto record = read_record(dir);
  if (!record) return "";
  std::string& head = record->head;
  const size_t at = head.find("\nfile " + name + " ");
  if (at == std::string::npos) return "";
  const size_t end = head.find('\n', at + 1);
  head.erase(at + 1, end == std::string::npos ? std::string::npos : end - at);
  return case_record_text(head + lines, record->summary);
}

// Drops a series: case.txt first (without the file's line, with `dropped
// NAME`), then the file; a crash between the two leaves a file case.txt
// does not record, which cache_problem refuses, so the case runs again.
bool drop_series_file(const std::string& dir, const std::string& name) {
  const std::string record = record_with(dir, name, "dropped " + name + "\n");
  if (record.empty()) return false;
  write_file_atomic(dir + "/" + kCaseRecordName, record);
  std::error_code ec;
  fs::remove(dir + "/" + name, ec);
  return true;
}

// Cuts series.csv.gz to the `columns` the pictures read, at plot precision:
// the file first, then case.txt with its new size and hash and
// `for-pictures NAME`; a crash between the two leaves a file whose hash
// case.txt does not match, so the case runs again. Returns the bytes saved;
// 0 if it was cut before.
unsigned long long cut_series_file(const std::string& dir, const std::set<std::string>& columns) {
  const std::string name = "series.csv.gz", path = dir + "/" + name;
  const auto record = read_record(dir);
  if (!record || record->head.find("\nfor-pictures " + name + "\n") != std::string::npos) return 0;
  std::string whole;
  try {
    whole = read_text_file(path);
  } catch (const std::exception&) {
    return 0;  // unfinished or missing: the cache check deals with it
  }
  const std::string csv = gzip_decompress(whole, kMaxInputFileBytes);
  const std::string cut = gzip_compress(csv_at_plot_precision(csv_select_columns(csv, columns)));
  const std::string line = "file " + name + " " + std::to_string(cut.size()) + " " + hash_hex(cut) + "\n";
  const std::string text = record_with(dir, name, line + "for-pictures " + name + "\n");
  if (text.empty() || cut.size() >= whole.size()) return 0;
  write_file_atomic(path, cut);
  write_file_atomic(dir + "/" + kCaseRecordName, text);
  return whole.size() - cut.size();
}

}  // namespace

SeriesShrunk shrink_series(const std::string& out_dir, const std::vector<MatrixCase>& cases, const SeriesUse& used) {
  SeriesShrunk done;
  for (const auto& c : cases) {
    if (c.keep_series) continue;
    const std::string dir = case_folder(out_dir, c.entry.id);
    if (const auto it = used.find(c.entry.id); it != used.end()) {
      const unsigned long long saved = cut_series_file(dir, it->second);
      done.reduced += saved > 0;
      done.reduced_bytes_saved += saved;
      continue;
    }
    for (const char* name : {"series.csv.gz", "series.csv"}) {
      std::error_code ec;
      const auto bytes = fs::file_size(dir + "/" + name, ec);
      if (ec || !drop_series_file(dir, name)) continue;
      ++done.dropped;
      done.dropped_bytes += bytes;
    }
  }
  return done;
}

}  // namespace cstab

// The benchmark matrix: a declarative file of sweeps, expanded into cases,
// each run (in a forked worker process) into DIR/cases/<case_id>/.
//
// File format (docs/matrix.md has the full reference): TOML 1.0, read by
// toml++. One optional [defaults] table, then any number of [[sweep]]
// tables; every key of a sweep may be a single value or an array, and a
// sweep is the Cartesian product of its arrays:
//
//     [defaults]
//     repeats = 3
//
//     [[sweep]]
//     name = "wp-rk4"
//     problems = "all"                  # or ["wheel", "ball"]
//     methods = "all"                   # applicable methods only
//     integrators = ["rk4", "adams"]
//     step = [1e-2, 1e-3, 1e-4]         # fixed-step integrators
//     t_end = "ref"                     # number | "ref" | "default"
//     param.lambda = [100, 1500]        # only for methods declaring it
//     problem_param.length = [1, 2]     # only for problems declaring it
//
// Expansion is deterministic (file order, then the order of every array,
// problems/methods in registry order for "all"). A case's id is a hash of
// its run configuration alone, so the same case keeps its folder and its id
// across rebuilds and matrices (thresholds and comparisons can name it); the
// cache key stored beside the result adds the binary's identity, so a case
// is rerun exactly when its configuration or the cstab binary changed.
#pragma once

#include <functional>
#include <iosfwd>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/problem.hpp"
#include "harness/run.hpp"
#include "io/hash.hpp"

namespace cstab {

// ---------------------------------------------------------------------------
// Parsing

struct SourceLocation {
  std::string file;
  int line = 0, column = 0;  // 1-based
  std::string str() const;   // "file:line:column"
};

// A malformed or inconsistent matrix file; what() is "file:line:col: message"
// (columns count UTF-8 code points, as toml++ does).
struct MatrixError : UsageError {
  MatrixError(const SourceLocation& where, const std::string& message)
      : UsageError(where.str() + ": " + message) {}
};

// A value of the file: TOML integers and floats are numbers (always finite;
// inf and nan are refused), dates and times and tables are refused.
struct MatrixValue {
  enum class Kind { kString, kNumber, kBool, kArray };
  Kind kind = Kind::kString;
  std::string text;  // string contents, or the number's source text ("1_000")
  double number = 0;
  bool boolean = false;
  std::vector<MatrixValue> items;  // kArray (never nested; kinds may mix)
  SourceLocation where;
};

struct MatrixEntry {
  // The path of nested tables down to the value joined with '.', whatever
  // the TOML spelling: "param.lambda" for `param.lambda = ..`,
  // `param = { lambda = .. }` or `lambda = ..` under [defaults.param].
  std::string key;
  SourceLocation where;  // the start of the key on its line
  MatrixValue value;
};

struct MatrixSection {
  std::string kind;  // "defaults" or "sweep"
  SourceLocation where;
  std::vector<MatrixEntry> entries;  // in file order
};

struct MatrixFile {
  std::string name;  // file name used in messages
  std::string text;  // verbatim source (stored in every results folder)
  std::vector<MatrixSection> sections;
};

// Throws MatrixError: for a TOML syntax error (toml++'s message) or what a
// matrix file cannot hold (a key outside a section, another section, a
// date, a nested array, inf/nan, a key part that is not a bare key).
MatrixFile parse_matrix(const std::string& text, const std::string& file_name);
MatrixFile read_matrix_file(const std::string& path);  // throws UsageError if unreadable
// The [defaults] `plugins` key's paths, as written (a string or an array of
// strings); MatrixError for anything else. Loaded before the file expands.
std::vector<std::string> matrix_plugins(const MatrixFile& file);

// ---------------------------------------------------------------------------
// Expansion

// What one results folder needs to know about a case without re-expanding
// the matrix (written to DIR/cases.csv; merge and report work from it).
// The end of a tuned curve's name (key `tune`): "pesterev/rk4 tuned".
inline constexpr std::string_view kTunedSuffix = " tuned";

struct CaseEntry {
  size_t index = 0;         // position in the full expansion (before filter/shard)
  std::string id;           // 16 hex digits
  std::string sweep;        // name of the [[sweep]] it came from
  std::string problem, method, formulation, integrator;
  std::string problem_params;  // given problem parameters, "a=1;b=2" (defaults not listed)
  std::string params;       // given parameters, "a=1;b=2" (defaults not listed)
  std::string setting;      // "step=0.001" or "tol=1e-08" or "rtol=..;atol=.."
  double t_end = 0;
  int repeats = 1;
  bool work_precision = true;  // a point of the problem's work-precision diagram
  bool overlay = false;        // candidate for the per-method time-series overlays
  std::string curve;           // work-precision curve: method/integrator[ params][ tuned]
  std::string label() const;   // one line for progress output
  // A case of a tuned curve (key `tune`): its curve ends in kTunedSuffix.
  bool tuned() const;
  std::string problem_label() const;  // "pendulum(length=2)", or the name alone
};

// The timeout of a case whose matrix gives none (key `timeout`): 600 s, far
// above the longest case of the default matrix; `timeout = 0` given
// explicitly means none.
inline constexpr double kDefaultCaseTimeout = 600;

struct MatrixCase {
  CaseEntry entry;
  RunConfig config;
  double timeout = kDefaultCaseTimeout;  // seconds, 0: none
  double repeat_if_under = 0;  // repeat only while a run takes less (seconds); 0: always
  // Keep the series even where no picture reads it (key `keep_series`, flag
  // --keep-series); not part of the configuration: a case whose series was
  // dropped runs again when it is asked for.
  bool keep_series = false;
  // An external case (key `external`): the shell command the worker runs,
  // its placeholders filled but {out} (the trajectory file it must write);
  // the case scores that trajectory. Empty: a cstab method.
  std::string external;
  std::string config_text;   // canonical configuration; id = hash(config_text)
  double cost_estimate = 0;  // relative, for scheduling and shard balance
};

struct MatrixCatalog {
  std::vector<const Problem*> problems;  // registry order
  std::vector<MethodInfo> methods;       // registry order
};

struct Expansion {
  std::vector<MatrixCase> cases;
  std::vector<std::string> notes;  // skipped combinations, duplicates, ...
};

// Throws MatrixError (with file:line:col) for any inconsistency.
Expansion expand_matrix(const MatrixFile& file, const MatrixCatalog& catalog);

// Cases whose label contains `filter` (empty: all), then shard k of n
// (1-based): cases ordered by estimated cost, dealt round-robin, so shards
// are disjoint, cover everything, and carry similar work. Result in
// expansion order.
std::vector<MatrixCase> select_cases(const std::vector<MatrixCase>& cases, const std::string& filter,
                                     int shard_k, int shard_n);
// "k/N" -> (k, N); throws UsageError.
std::pair<int, int> parse_shard(const std::string& text);

// hash_hex (case ids): io/hash.hpp.

// ---------------------------------------------------------------------------
// Running

struct MatrixRunOptions {
  std::string out_dir;
  int jobs = 1;
  bool force = false;          // rerun even if cached
  std::string binary_id;       // part of every cache key; "" or "unknown": nothing reused as cached
  std::string matrix_text;     // stored as DIR/matrix.toml
  size_t selected_cases = 0;   // cases after --filter, before --shard (merge checks coverage)
  std::function<const Problem&(const std::string&)> find_problem;
};

struct MatrixRunStats {
  size_t total = 0, run = 0, cached = 0, failed = 0, diverged = 0;
  size_t not_applicable = 0;  // rejected by the harness before running (status "invalid")
  size_t unfinished = 0;      // not run or killed unfinished (interrupted): rerun next time
  int interrupted_by = 0;     // SIGINT, SIGTERM or SIGHUP that stopped the matrix; 0: ran to the end
  // Workers that crashed, were killed from outside (not by their timeout)
  // or hit an I/O error: not recorded, not cached; the matrix exits 1.
  size_t infrastructure = 0;
  double seconds = 0;
};

// Runs every case not already complete in out_dir, `jobs` at a time, each in
// a forked process (a crash or a hang is a recorded result, never the end of
// the matrix). Writes DIR/cases.csv and DIR/matrix.toml first, then
// DIR/cases/<id>/{series.csv.gz, case.txt}; case.txt last (atomically), so
// a folder without it is incomplete. case.txt, the case's record, is the
// cache key, a line per result file and the case's summary rows:
//   problem=wheel                  the case's canonical configuration
//   ...                            (its hash is the case id)
//   binary=<size>-<16 hex>         the identity of the cstab binary
//   file series.csv.gz SIZE HASH   per result file beside it: bytes, 64-bit FNV-1a
//   for-pictures series.csv.gz     (or `dropped NAME`: shrink_series)
//   summary SIZE HASH              then SIZE bytes to the end of the file:
//   case_id,repeat,problem,...     the summary rows (CSV: header, one row
//   ...                            per repeat), verified like a file
// A case is reused only if its case.txt is whole, begins with the same
// configuration and binary, and every file it lists has its recorded size
// and hash (no unlisted result file beside it); otherwise it runs again and
// the progress says why. A folder of an older cstab (key.txt and
// summary.csv) runs again. Progress goes to `log`: one updating line on a
// terminal, plain lines otherwise.
//
// SIGINT, SIGTERM or SIGHUP (while it runs) stop the matrix cleanly: no new
// case starts, running workers get SIGTERM (SIGKILL after a grace period),
// a worker that still finished keeps its result, the folders of killed ones
// are removed, and run_matrix returns with `interrupted_by` set. A worker
// killed by one of these signals from outside is an unfinished case, never a
// `crashed` result. Rerunning resumes: finished cases are cached.
MatrixRunStats run_matrix(const std::vector<MatrixCase>& cases, const MatrixRunOptions& options,
                          std::ostream& log, bool log_is_tty);

// The series columns the report's pictures read, per case id; the first
// column (t) is always kept, and an empty set keeps every column.
using SeriesUse = std::map<std::string, std::set<std::string>>;

// After the report, the series of the finished cases in `cases` that do
// not keep them (keep_series): one no picture reads (not in `used`) is
// dropped (case.txt no longer lists it and says `dropped series.csv.gz`);
// one a picture reads is cut to the columns it reads, every number at plot
// precision (csv_select_columns, csv_at_plot_precision; case.txt records the
// new file and says `for-pictures series.csv.gz`), from which the report
// draws the same pictures. Either way the case stays cached unless
// keep_series later asks for its whole series.
struct SeriesShrunk {
  size_t dropped = 0, reduced = 0;
  unsigned long long dropped_bytes = 0, reduced_bytes_saved = 0;
};
SeriesShrunk shrink_series(const std::string& out_dir, const std::vector<MatrixCase>& cases, const SeriesUse& used);
// "SIGINT", "SIGTERM", "SIGHUP" (for messages about `interrupted_by`).
std::string stop_signal_name(int sig);

// The manifest DIR/cases.csv.
// `selected_cases`: how many cases the run was given before sharding.
void write_manifest(const std::string& path, const std::vector<CaseEntry>& entries, size_t selected_cases);
std::vector<CaseEntry> read_manifest(const std::string& path, size_t* selected_cases = nullptr);
// DIR/cases.csv of a results folder in expansion order; UsageError naming
// DIR if it is not a matrix results folder.
std::vector<CaseEntry> read_results_manifest(const std::string& dir);

// DIR/summary.csv: every case's summary rows (one per repeat) in expansion
// order, columns case_id, repeat, sweep, then the union of all cases'
// columns in order of first appearance. Cases without a complete result are
// left out and counted in the return value.
size_t write_matrix_summary(const std::string& dir, const std::vector<CaseEntry>& entries);

// Joins shard folders into out_dir: checks they ran the same matrix, copies
// the case folders, writes the union manifest, provenance of every shard
// and summary.csv. Returns the number of cases missing (not in any shard, or
// without a complete result).
size_t merge_results(const std::string& out_dir, const std::vector<std::string>& shard_dirs,
                     std::ostream& log);

// ---------------------------------------------------------------------------
// Small CSV reader (RFC 4180 quoting) for the files this suite writes.

struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> row_lines;                 // 1-based line each row starts on
  std::vector<std::vector<int>> row_columns;  // 1-based column each cell starts at
  int column(const std::string& name) const;  // -1 if absent
  const std::string& get(size_t row, const std::string& name) const;  // "" if absent
  // "path:line:column" of a cell (for messages).
  std::string where(size_t row, const std::string& name) const;
};
// Throws std::runtime_error if unreadable, UsageError (path:line:column) for
// an unterminated quote or a file over kMaxInputFileBytes.
CsvTable read_csv(const std::string& path);
std::string read_text_file(const std::string& path);  // as read_csv
// read_csv on text already read; `path` names it in messages.
CsvTable parse_csv(std::string text, const std::string& path);
// The largest file cstab reads (matrix files, thresholds, results CSVs).
inline constexpr size_t kMaxInputFileBytes = size_t(512) << 20;

}  // namespace cstab

// The results model: what a results folder (docs/matrix.md "The results
// folder", results/README.md) says about each case, parsed once. `cstab
// report`, the stress section, `cstab gate`, summary and merge all read a
// folder through load_results_folder; nothing else parses a case's
// summary rows (in its case.txt) or compares status text.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "matrix/matrix.hpp"

namespace cstab {

// The outcome of a case (the status column of summary.csv).
enum class Status {
  kOk,        // ran to t_end
  kDiverged,  // residual above the blow-up level, or non-finite state
  kFailed,    // the integrator gave up (step size underflow, Newton failure, exception)
  kTimeout,   // killed by the matrix after its timeout
  kCrashed,   // the worker died (signal, unexpected exit code)
  kInvalid,   // rejected before running: not applicable (n/a)
  kNotRun,    // no complete result in the folder
};

// "ok", "diverged", "failed", "timeout", "crashed", "invalid", "not run".
const char* status_name(Status s);
// The status a name stands for; nullopt for any other text.
std::optional<Status> parse_status(const std::string& text);
// A status summary.csv may hold: any but kNotRun (which is never written).
// Text that names no status reads as kFailed.
Status status_from_cell(const std::string& text);
// Statuses a thresholds file may expect (ok, diverged, failed): the gateable runs.
bool is_gateable(Status s);

constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

// One of a case's summary rows (one repeat; in its case.txt).
struct RepeatResult {
  Status status = Status::kFailed;
  std::string reason;
  double wall_seconds = kNoValue;
};

// One case of a results folder: its manifest entry and its parsed result.
// Metrics fold the repeats: the largest value over them (digits: the
// smallest); for the deterministic runs of this suite every repeat has the
// same values.
struct CaseResult {
  const CaseEntry* entry = nullptr;
  bool complete = false;             // a whole case.txt whose summary rows hold a row
  Status status = Status::kNotRun;   // the first repeat that is not ok, else ok
  std::string reason;                // of that repeat
  std::string formulation;           // as resolved by the run (summary.csv)
  double step = kNoValue, rtol = kNoValue, atol = kNoValue, t_end = kNoValue;
  long steps = -1, rejected_steps = -1, rhs_evals = -1;  // -1: not recorded
  double max_residual = kNoValue, final_residual = kNoValue;
  bool energy_law = false;
  double max_energy_drift = kNoValue;
  std::vector<std::pair<std::string, double>> max_integral_drifts;  // "max_<name>_drift" columns
  double max_integral_drift = kNoValue;  // largest of them
  double max_condition = kNoValue;
  double ref_time = kNoValue, ref_error = kNoValue, ref_scd = kNoValue;
  double perturb = kNoValue, initial_residual = kNoValue, recovery_time = kNoValue;
  bool recovered = false;
  double energy_drift_exponent = kNoValue;
  std::vector<std::pair<std::string, double>> integral_drift_exponents;  // "<name>_drift_exponent"
  // The drift the report shows: energy if the problem has an energy law,
  // else the largest first-integral drift; drift_name says which
  // ("energy", "first integrals (a, b)", "" for none).
  double drift = kNoValue;
  std::string drift_name;
  std::vector<RepeatResult> repeats;  // the summary rows, in order
  // the summary rows as read (header and rows), for the folder's DIR/summary.csv.
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;

  // Wall times over the repeats that finished (status ok): how many, their
  // median (median()), least and largest; NaN without one.
  int ok_repeats = 0;
  double wall_median = kNoValue, wall_min = kNoValue, wall_max = kNoValue;
  bool ok() const { return complete && status == Status::kOk; }
  const std::string& id() const { return entry->id; }
};

// The median of `values` (NaN if empty): the middle one, or the mean of the two.
double median(std::vector<double> values);

// A results folder: the manifest in expansion order and one CaseResult per
// entry (complete or not). CaseResult::entry points into `entries`, so a
// ResultsFolder is not copied.
struct ResultsFolder {
  std::string dir;
  std::vector<CaseEntry> entries;
  std::vector<CaseResult> cases;  // cases[i].entry == &entries[i]
  // "max_<name>_drift" and "<name>_drift_exponent" names over all cases, in
  // order of first appearance (the column order of DIR/summary.csv).
  std::vector<std::string> integral_names, exponent_names;
  ResultsFolder() = default;
  ResultsFolder(const ResultsFolder&) = delete;
  ResultsFolder& operator=(const ResultsFolder&) = delete;
  ResultsFolder(ResultsFolder&&) = default;
};

// Reads DIR/cases.csv and every case folder's record, cases/<id>/case.txt
// (complete only if it is whole: its summary rows have the size and hash it
// records). Throws UsageError if DIR is not a results folder.
ResultsFolder load_results_folder(const std::string& dir);
// The result of one case of `dir` (complete or not).
CaseResult load_case_result(const std::string& dir, const CaseEntry& entry);

// The record of a finished case, cases/<id>/case.txt (format: matrix.hpp,
// above run_matrix): a head (the cache key and the result files' lines),
// then a line `summary SIZE HASH` and the case's summary rows, SIZE bytes of
// CSV to the end of the file. Written atomically and last: it marks the
// case complete.
inline constexpr const char* kCaseRecordName = "case.txt";
struct CaseRecord {
  std::string head;     // every line before the `summary` line
  std::string summary;  // the summary rows (CSV text: header, one row per repeat)
};
// The text of a record: `head` (empty or ending in a newline), the
// `summary SIZE HASH` line of `summary`, then `summary`.
std::string case_record_text(const std::string& head, const std::string& summary);
// Splits a record's text at its first `summary` line. nullopt, with the
// reason in `why`, if there is none or the rows after it do not have the
// size and hash it records (a truncated or edited record).
std::optional<CaseRecord> parse_case_record(const std::string& text, std::string& why);

// cases/<id>/series.csv.gz (or series.csv) of a case; empty (no header, no rows) if it is
// missing or unreadable.
CsvTable load_case_series(const std::string& dir, const CaseEntry& entry);
// The path of a case's series: cases/<id>/series.csv.gz (what the matrix
// writes), else cases/<id>/series.csv (older folders); "" if neither exists.
std::string case_series_path(const std::string& dir, const CaseEntry& entry);

// Configuration keys ("step=0.001;perturb=1e-3", "a=1;b=2") compared by
// meaning: the same keys, each value equal as a number if both are
// numbers ("1e-3" == "0.001"), else as text; order does not matter.
bool same_key_values(const std::string& a, const std::string& b);
// The form same_key_values compares: keys sorted, numbers in shortest form.
std::string canonical_key_values(const std::string& text);

}  // namespace cstab

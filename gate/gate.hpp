// The regression gate: a versioned thresholds file names cases of a matrix
// results folder and the bounds their results must meet; `cstab gate`
// checks a results folder against it and fails on any violated bound.
//
// Thresholds file (CSV, read with fast-cpp-csv-parser; '#' starts a comment
// line; docs/gate.md is the reference). A row names one case by the fields
// of the results folder's cases.csv, and gives bounds; an empty cell is not
// checked:
//
//   key:    problem, method, integrator, setting (required; a perturbed
//           start is part of it: "step=0.001;perturb=0.001"), formulation,
//           params (the given parameters, "a=1;b=2"; empty: defaults),
//           (setting and params match by meaning: the same keys in any
//           order, numbers equal as numbers, so "step=1e-3" names the case
//           of "step=0.001"),
//           t_end (empty: any), sweep (empty: any),
//           name (a label other rows can name as their timing baseline)
//   bounds: status (expected status, default ok), max_residual,
//           max_final_residual (the residual at t_end: what stabilization
//           left of drift or of an inconsistent start), max_energy_drift,
//           max_integral_drift (largest first integral other than energy),
//           max_ref_error, min_ref_scd (significant correct digits),
//           max_recovery_time (from an inconsistent start, to the run's
//           recovery threshold), max_time_ratio with baseline (median wall
//           time over the baseline row's median wall time, same results
//           folder: never absolute seconds)
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/params.hpp"
#include "matrix/results.hpp"

namespace cstab {

struct ThresholdRow {
  int line = 0;                     // 1-based line in the file
  std::vector<std::string> fields;  // cells in the file's column order
  std::string name, sweep, problem, method, formulation, integrator, params, setting, baseline;
  double t_end = std::numeric_limits<double>::quiet_NaN();  // NaN: any
  Status status = Status::kOk;      // ok, diverged or failed
  double max_residual = std::numeric_limits<double>::quiet_NaN();  // NaN: not checked
  double max_final_residual = std::numeric_limits<double>::quiet_NaN();
  double max_energy_drift = std::numeric_limits<double>::quiet_NaN();
  double max_integral_drift = std::numeric_limits<double>::quiet_NaN();
  double max_ref_error = std::numeric_limits<double>::quiet_NaN();
  double min_ref_scd = std::numeric_limits<double>::quiet_NaN();
  double max_recovery_time = std::numeric_limits<double>::quiet_NaN();
  double max_time_ratio = std::numeric_limits<double>::quiet_NaN();
  std::string label() const;  // "wheel baumgarte rk4 step=0.001 [alpha=5]"
};

struct ThresholdsFile {
  std::string name;                  // file name used in messages
  std::vector<std::string> columns;  // header, in file order
  std::vector<std::string> lines;    // the file's lines, verbatim (comments survive --update)
  std::vector<ThresholdRow> rows;
};

// The columns a thresholds file may have, in the order --init writes them.
const std::vector<std::string>& threshold_columns();

// Throws UsageError "file:line:column: message" for unknown, missing or
// repeated columns, non-numbers, NaN/inf, negative bounds, unknown statuses,
// duplicate cases, dangling baselines.
ThresholdsFile parse_thresholds(const std::string& text, const std::string& file_name);
ThresholdsFile read_thresholds_file(const std::string& path);
// The file's text with every row's cells as they are now (comment lines kept).
std::string thresholds_text(const ThresholdsFile& file);

struct GateCheck {
  std::string case_label;
  int line = 0;           // thresholds line
  std::string check;      // status | max_residual | ... | max_time_ratio
  std::string value, threshold, margin;  // as printed (3 significant digits)
  double value_number = std::numeric_limits<double>::quiet_NaN();  // exact, for gate_csv
  bool pass = false;
  std::string note;       // why a check failed without a value (missing case, ...)
};

struct GateOutcome {
  std::vector<GateCheck> checks;
  size_t failed = 0;
  size_t unchecked_cases = 0;  // runs of the folder no row names (not a failure; n/a cases aside)
  std::vector<std::string> unchecked;  // their labels and ids ("label (id)"), for --strict
};

// Checks results folder `dir` (a `cstab matrix` output) against `file`.
// Throws UsageError if `dir` is not a results folder.
GateOutcome evaluate_gate(const ThresholdsFile& file, const std::string& dir);
std::string format_gate_table(const GateOutcome& outcome);
std::string gate_csv(const GateOutcome& outcome);

struct ThresholdChange {
  std::string case_label, column, old_value, new_value;
};

// How far a re-baselined bound sits from the measured value.
struct GateFactors {
  double value = 10;        // upper bounds: value x this (values below 1e-15 count as 1e-15);
                            // min_ref_scd: digits - log10(this)
  double time_ratio = 3;    // max_time_ratio: ratio x this (timing noise)
  double recovery = 1.5;    // max_recovery_time: time x this (deterministic; scales as 1/gain)
};

// Re-baselines every bound that a row sets from `dir`'s measured values
// (see GateFactors) and status from the measured status. Rows whose case is
// not in `dir` are kept and named in `notes`. Throws UsageError for factors
// below 1.
std::vector<ThresholdChange> update_thresholds(ThresholdsFile& file, const std::string& dir,
                                               const GateFactors& factors, std::vector<std::string>& notes);

// A new thresholds file with one row per completed case of `dir` and every
// bound the case has a value for (recovery time only for perturbed starts),
// set as update_thresholds would.
ThresholdsFile initial_thresholds(const std::string& dir, const GateFactors& factors, const std::string& file_name);

// --add-missing: appends to `file` one row per completed, gateable case of
// `dir` that no row names, built by the rule --init uses. Returns the
// labels of the rows added.
std::vector<std::string> add_missing_thresholds(ThresholdsFile& file, const std::string& dir,
                                                const GateFactors& factors);

}  // namespace cstab

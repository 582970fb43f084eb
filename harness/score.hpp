// Scoring a trajectory computed elsewhere (`cstab score`): the states of a
// CSV file, in a problem's canonical coordinates, go through the same
// observer as the states of `cstab run` (harness/recorder.hpp), so an outside
// simulator's output gets the same summary.csv and series.csv: residual per
// constraint, energy and first-integral drift, error against the reference,
// significant correct digits, recovery and the drift-growth exponent.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/problem.hpp"
#include "harness/run.hpp"

namespace cstab {

// A trajectory read for one problem: rows of the canonical coordinates.
struct Trajectory {
  std::vector<double> t;                 // strictly increasing
  std::vector<double> values;            // row-major, info.coordinates.size() per row
  std::vector<std::string> differenced;  // velocity columns computed by finite differences
  std::vector<std::string> ignored;      // columns a cstab series.csv adds (residual_*, *_drift, cond)
  double wall_seconds = std::numeric_limits<double>::quiet_NaN();  // from a "# wall_seconds = S" line
  size_t rows() const { return t.size(); }
};

// Reads `path` (CSV; .gz read as gzip): optional "#" comment lines first
// ("# wall_seconds = S" gives the producer's wall time), a header with t and
// the problem's coordinate names in any order, then one row per time. A
// missing velocity column NAMEdot whose position column NAME is there is
// differenced (second-order, non-uniform 3-point formulas) and listed in
// `differenced`. Throws UsageError "PATH:LINE:COLUMN: what is wrong" for a
// missing or unknown column, a cell that is not a finite number, a row of
// the wrong width, a t that does not increase, or too few rows (2; 3 where
// a column is differenced).
Trajectory read_trajectory(const std::string& path, const ProblemInfo& info);

struct ScoreConfig {
  std::string problem;
  std::vector<std::pair<std::string, std::string>> problem_params;  // name, value text (--problem-param)
  std::string formulation;  // empty: the one whose state is the canonical coordinates
  std::string label = "external";  // the summary's method column
  double ref_time = -1;     // < 0: the problem's default (if within the trajectory); 0: none
  double blowup = 1e3;
  double recovery_threshold = 1e-10;
  double drift_fit_from = 10;
  double sample_every = 0;  // series decimation; 0: span / 1000
  double wall_seconds = std::numeric_limits<double>::quiet_NaN();  // overrides the file's
  bool write_series = true;
};

// Scores the trajectory in `path` for `registered` (a variant of it with
// config.problem_params). Validates everything, the whole file included,
// before anything is written; with out_dir empty nothing is written. The
// summary's method column is config.label, its integrator "external";
// rhs_evals and rejected_steps are not recorded (empty cells); steps is
// the number of rows after the first. Extra columns: rows, differenced,
// ref_interpolation ("row": a row at the reference time; "cubic": through
// the four nearest rows) and initial_state_deviation (largest |difference|
// between the first row and the problem's own initial state).
RunResult score_trajectory(const Problem& registered, const ScoreConfig& config, const std::string& path,
                           const std::string& out_dir);

}  // namespace cstab

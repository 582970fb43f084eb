// What a results folder turns into: the work-precision table, the fastest
// method per accuracy level, the gnuplot pictures and one HTML page that
// shows them (linked from plots/, so report.html goes with its folder).
// Everything is derived from DIR/cases.csv, DIR/summary.csv and the case
// folders, so `cstab report DIR` can rebuild it at any time.
//
//   DIR/work_precision.csv   one row per work-precision case (tidy):
//       problem, curve, method, formulation, integrator, params, setting,
//       step, rtol, atol, t_end, case_id, sweep, repeats, status,
//       wall_median_s, wall_min_s, wall_max_s (over the repeats), steps,
//       rhs_evals, ref_time, ref_error (max |y - y_ref| at ref_time),
//       ref_scd (significant correct digits), max_residual, drift_quantity,
//       max_drift (energy if the problem has an energy law, otherwise the
//       largest first-integral drift)
//   DIR/fastest.csv          for each problem, error measure (ref_error,
//       max_residual, max_drift) and threshold (1e-4 ... 1e-12): every curve
//       that reaches it, ranked by the wall time of its fastest case
//       (columns problem, measure, threshold, rank, curve, method,
//       integrator, case_id, setting, wall_median_s, value, ratio_to_fastest)
//   DIR/plots/<problem>_{work_precision,overlay,trajectory}.png (and .svg
//       with ReportOptions::svg, `cstab report --svg`, or plots/replot.sh)
//   DIR/plots/data/*.dat.gz  the plotted data (gzip); DIR/plots/replot.sh redraws
//   DIR/report.html          tables, every picture (plots/*.png), provenance
#pragma once

#include <iosfwd>
#include <set>
#include <string>
#include <vector>

#include "matrix/matrix.hpp"

namespace cstab {

struct ReportOptions {
  int jobs = 1;               // gnuplot processes at a time
  bool plots = true;          // false: tables and HTML only
  bool svg = false;           // also draw every picture as SVG (plots/<name>.svg)
  std::string plot_scripts;   // folder of the gnuplot scripts; empty: find_plot_scripts()
};

struct ReportResult {
  std::string html;           // path of report.html
  size_t plots_drawn = 0, plots_reused = 0;
  std::vector<std::string> warnings;
  // The cases whose series the pictures read (overlays, trajectories, long
  // horizons), each with the columns read: what `cstab matrix` keeps when
  // it drops the other series (shrink_series).
  SeriesUse series_used;
};

// Needs DIR/summary.csv (write_matrix_summary). A picture whose data and
// script are unchanged since it was drawn is reused.
ReportResult build_report(const std::string& dir, const ReportOptions& options, std::ostream& log);

// The plots/ folder: $CSTAB_PLOTS, else the source tree's plots/, else
// ../../plots next to the executable; "" if none has work_precision.gp.
std::string find_plot_scripts();

// Accuracy levels of the "fastest method" tables.
const std::vector<double>& accuracy_levels();

}  // namespace cstab

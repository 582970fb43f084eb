// The "Scaling" section of a matrix report (issue 19): how each method's
// cost grows with a problem's size, from the cases of a results folder.
//
// A scaling study is found, not declared: the complete cases of one problem
// whose `problem_params` give exactly one parameter (a matrix's
// `problem_param.N = [5, 10, 20, 40]`), grouped into curves by
// method[formulation]/integrator and method parameters (the problem
// parameter left out, tuned cases left out). A curve with at least three
// sizes that have a finished case is drawn and fitted (the others are named):
//   * cost per step at each size: the median over the curve's finished
//     cases at that size of wall time (median of repeats) / steps;
//   * wall time at a fixed accuracy: the least wall time among them whose
//     error against the reference is <= the level; the level is the
//     tightest of 1e-1 .. 1e-12 at which some curve of the study has three
//     sizes (none if the problem has no reference);
//   * each exponent p: the least-squares slope of log cost against log size
//     (cost ~ size^p), over the curve's points.
// DIR/scaling.csv holds every point; the section has a table of exponents
// and one picture per study (plots/scaling.gp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "matrix/results.hpp"
#include "report/stress_report.hpp"

namespace cstab {

struct ScalingSection {
  bool empty = true;
  std::string html;               // tables (pictures are added by the report)
  std::vector<StressPlot> plots;  // one per study
};

// From the cases of a results folder; writes DIR/scaling.csv if it finds a study.
ScalingSection build_scaling_section(const ResultsFolder& folder);

// The least-squares slope of log y against log x over the points with
// x, y > 0 and finite; NaN with fewer than two such points or one x.
double fit_log_log_slope(const std::vector<std::pair<double, double>>& points);

}  // namespace cstab

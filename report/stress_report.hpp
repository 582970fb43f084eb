// The "Stress" section of a matrix report (issue 7): built from the regular
// cases of a results folder, so stress cases are gateable like any other.
//
//   * inconsistent starts: cases with perturb > 0 (matrix key `perturb`);
//     DIR/stress_perturb.csv, one row per case (problem, method, integrator,
//     setting, perturb, status, initial_residual, max_residual,
//     recovery_time, recovered, case_id); a table at delta = 1e-3 (or the
//     perturbation nearest to it) and per problem a picture of the peak
//     residual and the recovery time against delta, one curve per method;
//   * long horizons: cases of sweeps named long*; DIR/stress_long.csv
//     (drift growth exponents and their class: bounded < 0.25 <= ~sqrt(t)
//     < 0.75 <= ~linear < 1.5 <= faster) and per sweep the running max
//     |E(t) - E(0)| against t, log-log, from the series;
//   * stiffness: cases of sweeps named stiff*; DIR/stress_stiff.csv (gain =
//     the case's lambda/alpha parameter, wall time, error, residual) and per
//     problem wall time and error against the gain, one curve per
//     method[formulation]/integrator setting;
//   * near-singular motion: cases of sweeps named sharp*, a table of
//     error, residual and the largest condition number per case.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "matrix/results.hpp"

namespace cstab {

struct StressPlot {
  std::string name;     // basename under DIR/plots
  std::string script;   // gnuplot script in plots/
  std::string data;     // contents of DIR/plots/data/<name>.dat(.gz)
  std::string vars;     // extra gnuplot -e assignments ("; a=...")
  std::string caption;
};

struct StressSection {
  bool empty = true;
  std::string html;              // tables (pictures are added by the report)
  std::vector<StressPlot> plots;
  SeriesUse series_used;  // the series the pictures read: case id -> columns
};

// From the cases of a results folder; writes DIR/stress_*.csv for what it finds.
StressSection build_stress_section(const ResultsFolder& folder);

// "bounded", "~sqrt(t)", "~linear", "faster than linear", or "" for NaN.
std::string drift_growth_class(double exponent);

}  // namespace cstab

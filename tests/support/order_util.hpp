// What the convergence-order tests share (tests/unit/test_generalized_alpha.cpp,
// tests/regression/test_rattle.cpp): the least-squares slope of log(error)
// against log(h), and a tight run to measure errors against.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "problems/registry.hpp"

namespace cstab::testing {

// Least-squares slope of log(y) against log(x).
inline double log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    n += 1, sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// The final canonical state of projection on rk8pd at rtol = atol = 1e-13:
// a reference for every coordinate (some problems publish only positions).
inline std::vector<double> tight_reference(const std::string& problem, double t_end) {
  RunConfig cfg;
  cfg.problem = problem;
  cfg.method = "projection";
  cfg.integrator = "rk8pd";
  cfg.step.rtol = cfg.step.atol = 1e-13;
  cfg.t_end = t_end;
  cfg.ref_time = 0;
  cfg.write_series = false;
  const RunResult r = run_case(find_problem(problem), cfg, "");
  EXPECT_EQ(r.status, "ok") << r.reason;
  return r.final_state;
}

}  // namespace cstab::testing

// What the convergence-order tests share (tests/unit/test_generalized_alpha.cpp,
// tests/regression/test_rattle.cpp, tests/regression/test_symmetric_projection.cpp):
// the least-squares slope of log(error) against log(h), a tight run to
// measure errors against, and the second-order check of a scheme that
// steps itself.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <utility>
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

// `method` with `--integrator own` at h_max x {1, 1/2, 1/4, 1/10} to
// t_end, with `params`: the observed order of the position and velocity
// errors at t_end against tight_reference, each in [1.8, 2.2].
inline void expect_second_order(const std::string& problem, const std::string& method,
                                const std::vector<std::pair<std::string, std::string>>& params, double t_end,
                                double h_max) {
  const std::vector<double> ref = tight_reference(problem, t_end);
  ASSERT_FALSE(ref.empty());
  const size_t n = ref.size(), n_pos = n / 2;
  std::vector<double> hs, pos, vel;
  for (double f : {1.0, 0.5, 0.25, 0.1}) {
    RunConfig cfg;
    cfg.problem = problem;
    cfg.method = method;
    cfg.integrator = "own";
    cfg.step.step = h_max * f;
    cfg.t_end = t_end;
    cfg.ref_time = 0;
    cfg.write_series = false;
    cfg.params = params;
    const RunResult r = run_case(find_problem(problem), cfg, "");
    ASSERT_EQ(r.status, "ok") << problem << " h = " << cfg.step.step << ": " << r.reason;
    double ep = 0, ev = 0;
    for (size_t i = 0; i < n; ++i) {
      const double d = std::abs(r.final_state[i] - ref[i]);
      (i < n_pos ? ep : ev) = std::max(i < n_pos ? ep : ev, d);
    }
    hs.push_back(cfg.step.step), pos.push_back(ep), vel.push_back(ev);
    std::cout << "[ order    ] " << problem << " " << method << " h = " << cfg.step.step << ": position error " << ep
              << ", velocity error " << ev << "\n";
  }
  const double p = log_slope(hs, pos), v = log_slope(hs, vel);
  std::cout << "[ order    ] " << problem << " " << method << ": observed order positions " << p << ", velocities "
            << v << "\n";
  EXPECT_GE(p, 1.8) << problem;
  EXPECT_LE(p, 2.2) << problem;
  EXPECT_GE(v, 1.8) << problem;
  EXPECT_LE(v, 2.2) << problem;
}

}  // namespace cstab::testing

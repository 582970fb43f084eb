// Gain tuning (issue 22, `cstab tune`): the cheapest setting of a method's
// declared gain and of the step (fixed-step integrators) or tolerance
// (adaptive ones) that reaches a target on one measure.
//
// The search box is gains x levels (a level is a step or a tolerance,
// rtol = atol). Levels are walked from coarse to fine, every gain at a level
// before the next level; a gain stops at the first level that reaches the
// target. The assumption: for one gain, the cost grows as the level gets
// finer (more steps), so the first level that reaches is that gain's
// cheapest. A gain also stops once its next level is predicted to cost more
// than prune_ratio times the best found so far, in RHS evaluations (noise-
// free; fixed step: its count at this level times h_this / h_next;
// adaptive: at least its count at this level): such a level cannot be the
// best, nor within 20 % of it, if wall time follows RHS evaluations.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/params.hpp"
#include "core/problem.hpp"
#include "harness/run.hpp"

namespace cstab {

struct TuneConfig {
  RunConfig base;  // problem, method, integrator, t_end, other params, perturb
  // ref: RunResult::ref_error; residual: max_residual; drift:
  // max_energy_drift; final: final_residual (the residual at t_end: how far
  // a --perturb start has been damped).
  std::string measure = "ref";
  double target = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> gains;   // empty: default_tune_gains(the gain)
  std::vector<double> levels;  // steps or tolerances; empty: default_tune_levels
  int repeats = 3;             // timed runs of a setting that reaches the target
  std::string cost = "wall";   // wall: median wall_seconds; rhs: rhs_evals
  double prune_ratio = 10;     // 0: walk every level of every gain
  long max_runs = 2000;        // refused up front if gains x levels x repeats exceeds it
};

struct TuneRun {
  double gain = 0, level = 0;
  std::string status;  // ok | diverged | failed
  double value = std::numeric_limits<double>::quiet_NaN();  // the measure
  bool reached = false;
  int repeats = 0;          // runs made of this setting
  double wall = 0;          // median wall_seconds of the repeats
  long rhs_evals = 0;
  double cost = 0;          // wall or rhs_evals (TuneConfig::cost)
};

struct TuneResult {
  ParamSpec gain;           // the tuned parameter
  bool fixed_step = true;   // levels are steps (else tolerances)
  std::vector<double> gains, levels;  // the search box, levels coarse to fine
  std::vector<TuneRun> runs;          // every setting tried, in run order
  bool reachable = false;
  TuneRun best;             // the least cost (ties: the smaller measure value)
  // Each gain's first reaching run (its cheapest), in gain order; a gain
  // that reached nothing within the box has none.
  std::vector<TuneRun> per_gain;
  // The gains whose own cheapest cost is within 20 % of the best.
  double flat_min = 0, flat_max = 0;
  int flat_count = 0;
  long case_runs = 0;       // run_case calls, repeats included
  double seconds = 0;       // wall time of the whole search
};

// `n` (>= 2) log-spaced values over 3 decades around the default (default x
// 10^(-1.5 .. 1.5), 3 significant digits), clipped to the spec's bound,
// duplicates dropped; default_tune_gains: 13 of them (4 a decade).
std::vector<double> tune_gains(const ParamSpec& gain, int n);
std::vector<double> default_tune_gains(const ParamSpec& gain);
// Fixed step: 13 steps 1e-1 .. 1e-4 (4 a decade, 3 significant digits);
// adaptive: 9 tolerances 1e-3 .. 1e-11.
std::vector<double> default_tune_levels(bool fixed_step);

// Checks the configuration (throws UsageError naming the flag) and makes
// one short probe run of the method; runs nothing else.
void check_tune(const Problem& problem, const TuneConfig& config);

// Runs the search (check_tune first).
TuneResult tune(const Problem& problem, const TuneConfig& config);

// The measure of a run (NaN if it has none).
double tune_measure(const RunResult& r, const std::string& measure);

}  // namespace cstab

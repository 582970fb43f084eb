// cstab tune (declare_tune lists the options; --help prints them; the search
// is harness/tune.hpp). Writes DIR/tune.csv (every setting tried), DIR/best.csv
// (the cheapest setting that reaches the target, or `unreachable`) and, if
// gnuplot is present, DIR/tune.png (cost against gain).

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "harness/tune.hpp"
#include "io/csv.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

void declare_tune(Args& a) {
  const TuneConfig d;
  const RunConfig r;
  a.required("--problem", "P", "problem (`cstab list` lists them)")
      .repeatable("--problem-param", "NAME=VALUE", "problem parameter (`cstab list`: each with its default and range)")
      .required("--method", "M", "stabilization method with a declared gain (`cstab list`)")
      .value("--formulation", "F", "formulation of the problem (default: the method's own)")
      .repeatable("--param", "NAME=VALUE", "other method parameter (not the tuned gain)")
      .required("--integrator", "I", "integrator (`cstab list`)")
      .value("--t-end", "T", "end time: a number, `ref` (the problem's reference time) or `default` (its horizon)",
             "default")
      .required("--target", "E", "the measure must end at or below E (> 0)")
      .value("--measure", "M",
             "ref: error against the reference; residual: max residual; drift: max energy drift; final: residual "
             "at t_end (with --perturb: how far the perturbation was damped)",
             d.measure)
      .value("--steps", "H1,H2,...", "steps searched (fixed-step integrators; default 13 steps 1e-1 .. 1e-4)")
      .value("--tols", "T1,T2,...", "tolerances searched, rtol = atol (adaptive; default 1e-3 .. 1e-11)")
      .value("--gains", "G1,G2,...", "gains searched (default: 13 log-spaced over 3 decades around the default)")
      .value("--repeats", "N", "timed runs of each setting that reaches the target; cost is their median",
             std::to_string(d.repeats))
      .value("--cost", "C", "wall or rhs: what `cheapest` means: median wall seconds, or RHS evaluations (noise-free)",
             d.cost)
      .value("--perturb", "DELTA", "start off the constraint manifold by DELTA (as `cstab run --perturb`)", "0")
      .value("--blowup", "B", "residual above which a run is diverged (never reaches the target)",
             format_short(r.blowup))
      .value("--prune-ratio", "R",
             "a gain stops walking to finer steps/tols once the next is predicted to take more than R x the best's "
             "RHS evaluations (0: never)",
             format_short(d.prune_ratio))
      .value("--max-runs", "N", "refuse a search box (gains x steps x repeats) of more runs than this",
             std::to_string(d.max_runs))
      .value("--max-steps", "N", "most steps of one run (a fixed step needing more is refused up front)",
             format_short(r.max_steps))
      .flag("--no-plot", "do not draw tune.png (gnuplot)")
      .required("--out", "DIR", "output folder (created if missing)");
}

namespace {

TuneConfig read_tune(const Args& args, const Problem& problem) {
  TuneConfig cfg;
  RunConfig& b = cfg.base;
  b.problem = args.require("--problem");
  b.problem_params = args.pairs("--problem-param");
  b.method = args.require("--method");
  b.formulation = args.get("--formulation");
  b.integrator = args.require("--integrator");
  const IntegratorInfo& integ = find_integrator(b.integrator);
  b.params = args.pairs("--param");
  b.t_end = resolve_end_time(args.get("--t-end"), problem.info(), "--t-end");
  b.perturb = args.number("--perturb");
  b.blowup = args.number("--blowup");
  if (!(b.blowup > 0)) throw UsageError("--blowup: must be > 0");
  b.max_steps = args.number("--max-steps");
  if (!(b.max_steps >= 1 && b.max_steps <= 1e15)) throw UsageError("--max-steps: must be a number in [1, 1e15]");
  cfg.target = args.number("--target");
  cfg.measure = args.get("--measure");
  cfg.cost = args.get("--cost");
  if (integ.fixed_step && args.has("--tols"))
    throw UsageError("--tols: integrator '" + integ.name + "' is fixed-step; give --steps");
  if (!integ.fixed_step && args.has("--steps"))
    throw UsageError("--steps: integrator '" + integ.name + "' is adaptive; give --tols");
  cfg.levels = args.number_list(integ.fixed_step ? "--steps" : "--tols");
  cfg.gains = args.number_list("--gains");
  const long repeats = args.integer("--repeats");
  if (repeats < 1 || repeats > 100) throw UsageError("--repeats: must be in [1, 100]");
  cfg.repeats = int(repeats);
  cfg.prune_ratio = args.number("--prune-ratio");
  const long max_runs = args.integer("--max-runs");
  if (max_runs < 1) throw UsageError("--max-runs: must be >= 1");
  cfg.max_runs = max_runs;
  return cfg;
}

std::string cell(double v) { return std::isfinite(v) ? format_exact(v) : ""; }

// 4 significant digits for the tables people read; "-" for none.
std::string g4(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Every setting tried, one row each.
std::string tune_grid_csv(const TuneConfig& cfg, const TuneResult& res, const std::string& level_name) {
  const RunConfig& b = cfg.base;
  std::string grid = "problem,method,integrator,gain_param,gain," + level_name +
                     ",measure,value,target,reached,status,wall_median,repeats,rhs_evals,cost\n";
  for (const auto& r : res.runs)
    grid +=
        csv_line({b.problem, b.method, b.integrator, res.gain.name, format_exact(r.gain), format_exact(r.level),
                  cfg.measure, cell(r.value), format_exact(cfg.target), r.reached ? "yes" : "no", r.status,
                  format_exact(r.wall), std::to_string(r.repeats), std::to_string(r.rhs_evals), format_exact(r.cost)});
  return grid;
}

// The closest any run came (least measure value of a run that finished).
double closest_value(const TuneResult& res) {
  double closest = NAN;
  for (const auto& r : res.runs)
    if (r.status == "ok" && std::isfinite(r.value) && !(r.value >= closest)) closest = r.value;
  return closest;
}

// best.csv: the cheapest setting that reaches the target, or `unreachable`.
std::vector<std::pair<std::string, std::string>> tune_best_row(const TuneConfig& cfg, const TuneResult& res,
                                                               const std::string& level_name) {
  const RunConfig& b = cfg.base;
  const TuneRun& best = res.best;
  const bool ok = res.reachable;
  return {
      {"problem", b.problem},
      {"method", b.method},
      {"integrator", b.integrator},
      {"measure", cfg.measure},
      {"target", format_exact(cfg.target)},
      {"result", ok ? "ok" : "unreachable"},
      {"gain_param", res.gain.name},
      {"gain", ok ? format_exact(best.gain) : ""},
      {level_name, ok ? format_exact(best.level) : ""},
      {"value", ok ? cell(best.value) : ""},
      {"wall_median", ok ? format_exact(best.wall) : ""},
      {"rhs_evals", ok ? std::to_string(best.rhs_evals) : ""},
      {"cost", ok ? format_exact(best.cost) : ""},
      {"cost_kind", cfg.cost},
      {"flat_gain_min", ok ? format_exact(res.flat_min) : ""},
      {"flat_gain_max", ok ? format_exact(res.flat_max) : ""},
      {"flat_gains", ok ? std::to_string(res.flat_count) : ""},
      {"closest_value", cell(closest_value(res))},
      {"runs", std::to_string(res.case_runs)},
      {"seconds", format_exact(res.seconds)},
  };
}

// Cost against gain at the best setting's step or tolerance: one line per gain.
void print_cost_against_gain(const TuneConfig& cfg, const TuneResult& res, const std::string& level_name) {
  const TuneRun& best = res.best;
  std::printf("cost against gain at %s = %s (cheapest: each gain's first %s that reaches)\n", level_name.c_str(),
              g4(best.level).c_str(), level_name.c_str());
  std::printf("  %-12s %-10s %-8s %-11s %-10s %-14s %s\n", res.gain.name.c_str(), cfg.measure.c_str(), "reached",
              "wall (s)", "rhs", ("cheapest " + level_name).c_str(), "cheapest cost / best");
  for (double g : res.gains) {
    const TuneRun* at = nullptr;
    const TuneRun* own = nullptr;
    for (const auto& r : res.runs)
      if (r.gain == g) {
        if (r.level == best.level) at = &r;
        if (r.reached) own = &r;
      }
    std::printf("  %-12s %-10s %-8s %-11s %-10s %-14s %s\n", g4(g).c_str(), at ? g4(at->value).c_str() : "-",
                at ? (at->reached          ? "yes"
                      : at->status == "ok" ? "no"
                                           : at->status.c_str())
                   : "-",
                at ? g4(at->wall).c_str() : "-", at ? std::to_string(at->rhs_evals).c_str() : "-",
                own ? g4(own->level).c_str() : "-", own ? g4(own->cost / best.cost).c_str() : "-");
  }
}

// The search's budget, its best setting and how flat the optimum is.
void print_tune(const TuneConfig& cfg, const TuneResult& res, const std::string& level_name) {
  const RunConfig& b = cfg.base;
  const std::string& gname = res.gain.name;
  const TuneRun& best = res.best;
  std::printf("%s / %s / %s: tune %s for %s <= %s (cost: %s)\n", b.problem.c_str(), b.method.c_str(),
              b.integrator.c_str(), gname.c_str(), cfg.measure.c_str(), format_short(cfg.target).c_str(),
              cfg.cost == "rhs" ? "RHS evaluations" : "median wall seconds");
  std::printf("budget: %zu gains x %zu %ss (box of %zu settings); %zu settings tried, %ld runs, %.3g s\n",
              res.gains.size(), res.levels.size(), level_name.c_str(), res.gains.size() * res.levels.size(),
              res.runs.size(), res.case_runs, res.seconds);
  if (!res.reachable) {
    const double closest = closest_value(res);
    std::printf("unreachable: no setting in the search box reaches %s <= %s (closest: %s)\n", cfg.measure.c_str(),
                format_short(cfg.target).c_str(), std::isfinite(closest) ? format_3g(closest).c_str() : "none");
    return;
  }
  std::printf("best: %s = %s, %s = %s: %s = %s, wall %.4g s (median of %d), %ld rhs evals\n", gname.c_str(),
              g4(best.gain).c_str(), level_name.c_str(), g4(best.level).c_str(), cfg.measure.c_str(),
              format_3g(best.value).c_str(), best.wall, best.repeats, best.rhs_evals);
  std::printf("flat optimum: %d gain(s) within 20 %% of the best cost, %s in [%s, %s]\n", res.flat_count, gname.c_str(),
              g4(res.flat_min).c_str(), g4(res.flat_max).c_str());
  if (res.gains.size() > 1 && (best.gain == res.gains.front() || best.gain == res.gains.back()))
    std::printf("note: the best gain is at the edge of the search box; a wider --gains may find a cheaper one\n");
  print_cost_against_gain(cfg, res, level_name);
}

}  // namespace

int cmd_tune(const Args& args) {
  const Problem& problem = find_problem(args.require("--problem"));
  const TuneConfig cfg = read_tune(args, problem);
  const std::string out = args.require("--out");
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
    throw UsageError("--out " + out + ": exists and is not a folder");
  check_tune(problem, cfg);

  const TuneResult res = tune(problem, cfg);
  const std::string level_name = res.fixed_step ? "step" : "tol";
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw UsageError("--out " + out + ": cannot create folder: " + ec.message());
  write_file_atomic(out + "/tune.csv", tune_grid_csv(cfg, res, level_name));
  write_file_atomic(out + "/best.csv", key_value_csv(tune_best_row(cfg, res, level_name)));
  print_tune(cfg, res, level_name);
  if (!args.has("--no-plot") && res.reachable && std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string cmd = "gnuplot -e \"dir='" + out + "'\" " CSTAB_SOURCE_DIR "/plots/tune.gp";
    if (std::system(cmd.c_str()) != 0) std::cerr << "cstab tune: warning: gnuplot failed\n";
  }
  std::cout << "wrote " << out << "/tune.csv and best.csv\n";
  return 0;
}

}  // namespace cstab::cli

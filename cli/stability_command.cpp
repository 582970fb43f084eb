// cstab stability (declare_stability lists the options; --help prints them).
// Writes DIR/stability.csv (the h x gain map), DIR/boundary.csv (per step:
// the measured boundary in h*rate and the integrator's theoretical real
// stability interval) and, if gnuplot is present, DIR/stability.png/.svg.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "io/csv.hpp"
#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "harness/stability.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

void declare_stability(Args& a) {
  const StabilityConfig d;
  declare_case_options(a);
  a.required("--gain-param", "NAME", "the method parameter swept as the gain (lambda, alpha, dt, ...)")
      .required("--steps", "H1,H2,...", "fixed steps of the map, each > 0")
      .required("--gains", "G1,G2,...", "gains of the map, each > 0")
      .value("--blowup", "B", "residual above which a run counts as unstable", "1")
      .value("--bisect", "N", "bisection steps of the boundary search per step, in [0, 60]",
             std::to_string(d.bisection_iterations))
      .value("--max-steps", "N",
             "most integration steps of the whole map and boundary search, estimated up front as "
             "sum over steps h of t_end / h x (gains + bisect + 2)",
             "1e9")
      .flag("--no-plot", "do not draw stability.png/.svg (gnuplot)")
      .required("--out", "DIR", "output folder (created if missing)");
}

namespace {

// Everything but the output folder, checked before any file is written.
StabilityConfig read_stability(const Args& args, const Problem& problem) {
  StabilityConfig cfg;
  cfg.base.problem = args.require("--problem");
  cfg.base.problem_params = args.pairs("--problem-param");
  cfg.base.method = args.require("--method");
  cfg.base.formulation = args.get("--formulation");
  cfg.base.integrator = args.require("--integrator");
  if (!find_integrator(cfg.base.integrator).fixed_step)
    throw UsageError("--integrator " + cfg.base.integrator + ": stability maps need a fixed-step integrator");
  cfg.gain_param = args.require("--gain-param");
  for (const auto& [name, value] : args.pairs("--param")) {
    if (name == cfg.gain_param)
      throw UsageError("--param " + name + "=" + value + ": that is the swept --gain-param");
    cfg.base.params.emplace_back(name, value);
  }
  cfg.steps = args.number_list("--steps");
  cfg.gains = args.number_list("--gains");
  for (double h : cfg.steps)
    if (!(h > 0)) throw UsageError("--steps: " + format_short(h) + " must be > 0");
  for (double g : cfg.gains)
    if (!(g > 0)) throw UsageError("--gains: " + format_short(g) + " must be > 0");
  cfg.base.t_end = args.end_time("--t-end", problem.info());
  if (!(cfg.base.t_end > 0)) throw UsageError("--t-end: must be > 0");
  cfg.base.blowup = args.number("--blowup");
  if (!(cfg.base.blowup > 0)) throw UsageError("--blowup: must be > 0");
  const long bisect = args.integer("--bisect");
  // 60 halvings take any bracket below double resolution.
  if (bisect < 0 || bisect > 60) throw UsageError("--bisect: must be in [0, 60]");
  cfg.bisection_iterations = int(bisect);
  // Every map ends: the work is bounded before anything runs.
  const double budget = args.number("--max-steps");
  if (!(budget >= 1 && budget <= 1e15)) throw UsageError("--max-steps: must be a number in [1, 1e15]");
  if (cfg.steps.size() > 100000 || cfg.gains.size() > 100000)
    throw UsageError("--steps/--gains: at most 100000 values each");
  double total = 0;
  for (double h : cfg.steps) total += std::ceil(cfg.base.t_end / h) * double(cfg.gains.size() + cfg.bisection_iterations + 2);
  if (!(total <= budget))
    throw UsageError("--steps/--gains/--bisect: the map needs about " + format_short(total) +
                     " integration steps, more than the limit of " + format_short(budget) +
                     " (--max-steps raises it)");
  cfg.base.max_steps = budget;
  return cfg;
}

}  // namespace

int cmd_stability(const Args& args) {
  const Problem& problem = find_problem(args.require("--problem"));
  const StabilityConfig cfg = read_stability(args, problem);
  const std::string out = args.require("--out");

  // Validate the combination (method, gain parameter) with one cheap run
  // before creating any file.
  {
    RunConfig probe = cfg.base;
    probe.step.step = cfg.steps.front();
    probe.t_end = cfg.steps.front();
    probe.ref_time = 0;
    probe.write_series = false;
    probe.params.emplace_back(cfg.gain_param, "1");
    run_case(problem, probe, "");
  }

  const auto map = stability_map(problem, cfg);
  const auto bounds = stability_boundaries(problem, cfg);

  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw UsageError("--out " + out + ": cannot create folder: " + ec.message());
  std::string grid = "problem,method,integrator,gain_param,step,gain,rate,h_rate,status,max_residual,final_residual,fail_time\n";
  for (const auto& p : map)
    grid += cfg.base.problem + "," + cfg.base.method + "," + cfg.base.integrator + "," + cfg.gain_param + "," +
            format_exact(p.step) + "," + format_exact(p.gain) + "," + format_exact(p.rate) + "," +
            format_exact(p.step * p.rate) + "," + p.status + "," + format_exact(p.max_residual) + "," +
            format_exact(p.final_residual) + "," + (std::isnan(p.fail_time) ? "" : format_exact(p.fail_time)) + "\n";
  write_file_atomic(out + "/stability.csv", grid);
  std::string bcsv = "problem,method,integrator,gain_param,step,stable_rate,unstable_rate,measured_h_rate,theory_h_rate,ratio\n";
  std::cout << "step        measured h*rate   theory   ratio\n";
  for (const auto& b : bounds) {
    bcsv += cfg.base.problem + "," + cfg.base.method + "," + cfg.base.integrator + "," + cfg.gain_param + "," +
            format_exact(b.step) + "," + format_exact(b.stable_rate) + "," + format_exact(b.unstable_rate) + "," +
            format_exact(b.measured) + "," + format_exact(b.theory) + "," + format_exact(b.measured / b.theory) + "\n";
    std::printf("%-10.3g  %-16.4g  %-7.4g  %.3f\n", b.step, b.measured, b.theory, b.measured / b.theory);
  }
  write_file_atomic(out + "/boundary.csv", bcsv);
  if (!args.has("--no-plot") && std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string cmd = "gnuplot -e \"dir='" + out + "'\" " CSTAB_SOURCE_DIR "/plots/stability.gp";
    if (std::system(cmd.c_str()) != 0) std::cerr << "cstab stability: warning: gnuplot failed\n";
  }
  std::cout << "wrote " << out << "/stability.csv and boundary.csv\n";
  return 0;
}

}  // namespace cstab::cli

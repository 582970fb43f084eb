// cstab stability (declare_stability lists the options; --help prints them).
// Writes DIR/stability.csv (the h x gain map), DIR/boundary.csv (a gain on
// an integrator with a real stability interval: per step, the measured
// boundary in h*rate and that interval; otherwise per parameter value, the
// largest stable step) and, if gnuplot is present, DIR/stability.png/.svg.

#include <algorithm>
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
  a.required("--gain-param", "NAME",
             "the method parameter swept: a gain (lambda, alpha, dt, ...; boundary in h * rate) or any other "
             "(rho_inf, ...; boundary in the step)")
      .required("--steps", "H1,H2,...", "fixed steps of the map, each > 0")
      .required("--gains", "G1,G2,...", "values of the swept parameter, each within its range (a gain: > 0)")
      .value("--perturb", "DELTA",
             "start off the constraint manifold by DELTA (as `cstab run --perturb`): a start at rest on it "
             "would never show the feedback's instability",
             "0")
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
  if (cfg.steps.empty() || cfg.gains.empty()) throw UsageError("--steps/--gains: give at least one value each");
  cfg.base.t_end = args.end_time("--t-end", problem.info());
  if (!(cfg.base.t_end > 0)) throw UsageError("--t-end: must be > 0");
  cfg.base.perturb = args.number("--perturb");
  if (!(cfg.base.perturb >= 0)) throw UsageError("--perturb: must be >= 0");
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
  // The parameter swept, and its values within its bound (a gain > 0;
  // rho_inf in [0, 1]; HHT's alpha in [-1/3, 0]).
  const ParamSpec spec = gain_spec(problem, cfg);
  for (double g : cfg.gains)
    if (const std::string why = param_value_problem(spec, g); !why.empty())
      throw UsageError("--gains: " + format_short(g) + ": " + spec.name + " " + why);
  double total = 0;
  const double smallest = *std::min_element(cfg.steps.begin(), cfg.steps.end());
  if (boundary_in_rate(spec, cfg.base.integrator)) {
    for (double h : cfg.steps)
      total += std::ceil(cfg.base.t_end / h) * double(cfg.gains.size() + cfg.bisection_iterations + 2);
  } else {
    for (double h : cfg.steps) total += std::ceil(cfg.base.t_end / h) * double(cfg.gains.size());
    total += std::ceil(cfg.base.t_end / smallest) * double(cfg.gains.size() * cfg.bisection_iterations);
  }
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
  const ParamSpec spec = gain_spec(problem, cfg);

  // Validate the combination (method, gain parameter) with one cheap run
  // before creating any file.
  {
    RunConfig probe = cfg.base;
    probe.step.step = cfg.steps.front();
    probe.t_end = cfg.steps.front();
    probe.ref_time = 0;
    probe.write_series = false;
    apply_gain(probe, spec, cfg.gains.front());
    run_case(problem, probe, "");
  }
  const bool in_rate = boundary_in_rate(spec, cfg.base.integrator);
  const auto map = stability_map(problem, cfg);
  // Every run before any file: the boundary in h * rate, or in the step.
  const auto rate_bounds = in_rate ? stability_boundaries(problem, cfg) : std::vector<StabilityBoundary>{};
  const auto step_bounds = in_rate ? std::vector<StepBoundary>{} : step_boundaries(problem, cfg, map);

  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw UsageError("--out " + out + ": cannot create folder: " + ec.message());
  auto num = [](double x) { return std::isnan(x) ? std::string() : format_exact(x); };
  const std::string key = cfg.base.problem + "," + cfg.base.method + "," + cfg.base.integrator + "," + cfg.gain_param + ",";
  std::string grid = "problem,method,integrator,gain_param,step,gain,rate,h_rate,status,max_residual,final_residual,fail_time\n";
  for (const auto& p : map)
    grid += key + format_exact(p.step) + "," + format_exact(p.gain) + "," + num(p.rate) + "," + num(p.step * p.rate) +
            "," + p.status + "," + format_exact(p.max_residual) + "," + format_exact(p.final_residual) + "," +
            num(p.fail_time) + "\n";
  write_file_atomic(out + "/stability.csv", grid);
  std::string bcsv;
  if (in_rate) {
    bcsv = "problem,method,integrator,gain_param,step,stable_rate,unstable_rate,measured_h_rate,theory_h_rate,ratio\n";
    std::cout << "step        measured h*rate   theory   ratio\n";
    for (const auto& b : rate_bounds) {
      bcsv += key + format_exact(b.step) + "," + num(b.stable_rate) + "," + num(b.unstable_rate) + "," +
              num(b.measured) + "," + format_exact(b.theory) + "," + num(b.measured / b.theory) + "\n";
      std::printf("%-10.3g  %-16.4g  %-7.4g  %.3f\n", b.step, b.measured, b.theory, b.measured / b.theory);
    }
  } else {
    // No real stability interval to compare with: the largest stable step
    // per value of the parameter.
    bcsv = "problem,method,integrator,gain_param,gain,stable_step,unstable_step\n";
    std::printf("%-12s  %-19s  %s\n", cfg.gain_param.c_str(), "largest stable step", "smallest unstable step");
    auto step = [](double h) {
      char text[32];
      std::snprintf(text, sizeof text, "%.4g", h);
      return std::isnan(h) ? std::string("none of the grid") : std::string(text);
    };
    for (const auto& b : step_bounds) {
      bcsv += key + format_exact(b.gain) + "," + num(b.stable_step) + "," + num(b.unstable_step) + "\n";
      const std::string stable = step(b.stable_step), unstable = step(b.unstable_step);
      std::printf("%-12.6g  %-19s  %s\n", b.gain, stable.c_str(), unstable.c_str());
    }
  }
  write_file_atomic(out + "/boundary.csv", bcsv);
  if (!args.has("--no-plot") && std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string cmd = "gnuplot -e \"dir='" + out + "'; mode='" + (in_rate ? "rate" : "step") + "'\" " CSTAB_SOURCE_DIR
                            "/plots/stability.gp";
    if (std::system(cmd.c_str()) != 0) std::cerr << "cstab stability: warning: gnuplot failed\n";
  }
  std::cout << "wrote " << out << "/stability.csv and boundary.csv\n";
  return 0;
}

}  // namespace cstab::cli

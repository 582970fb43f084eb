#include "cli/commands.hpp"

#include <iostream>
#include <sstream>

#include "cli/args.hpp"
#include "cli/gate_command.hpp"
#include "cli/stability_command.hpp"
#include "cli/matrix_commands.hpp"
#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "harness/run.hpp"
#include "methods/pair.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

std::string usage() {
  return R"(cstab - benchmark and verification suite for constraint stabilization methods

usage:
  cstab list
  cstab run --problem P --method M [--formulation F] [--param name=value ...]
            --integrator I (--step H | --rtol R --atol A) --t-end T
            [--times t1,t2,...] [--sample-every DT] [--ref-time T]
            [--blowup B] [--observe-every N] [--perturb DELTA]
            [--recovery-threshold R] [--drift-fit-from T] --out DIR
  cstab stability --problem P --method M --integrator I --gain-param NAME
            --steps h1,h2,... --gains g1,g2,... --t-end T --out DIR [--param k=v ...]
  cstab matrix [FILE] --out DIR [--jobs N] [--shard k/N] [--filter S] [--force]
               [--no-report] [--list] [--print-default]
               runs a benchmark matrix (default: the embedded one; docs/matrix.md)
  cstab merge OUT SHARD_DIR... [--jobs N] [--no-report]
  cstab report DIR [--jobs N] [--no-plots]
  cstab gate [--thresholds FILE] [--csv OUT] DIR
               checks a matrix results folder against accuracy thresholds (docs/gate.md);
               exit 1 if any check fails
  cstab gate --update [--factor F] [--time-factor T] [--thresholds FILE] DIR
  cstab gate --init FILE [--factor F] DIR

Exit codes: 0 success (a diverged run is a recorded result), 2 bad input, 1 internal error.
See README.md for every column of summary.csv and series.csv.
)";
}

namespace {

std::string bound_text(Bound b) {
  switch (b) {
    case Bound::kPositive: return "> 0";
    case Bound::kNonNegative: return ">= 0";
    default: return "any";
  }
}

int cmd_list(const std::vector<std::string>& argv) {
  Args args(argv, {});
  if (!args.positional().empty()) throw UsageError("list: unexpected argument '" + args.positional()[0] + "'");
  std::ostringstream out;
  out << "PROBLEMS\n";
  for (const auto& p : all_problems()) {
    const auto& info = p->info();
    out << "  " << info.name << ": " << info.description << "\n";
    out << "    coordinates: ";
    for (size_t i = 0; i < info.coordinates.size(); ++i) out << (i ? "," : "") << info.coordinates[i];
    out << "\n    first integrals: " << (info.has_energy ? "energy" : "none (no energy law)");
    for (const auto& fi : info.first_integrals) out << ", " << fi;
    out << "\n    reference: "
        << (info.reference_time > 0 ? info.reference_description + " (default at t = " +
                                          format_short(info.reference_time) + ")"
                                    : std::string("none"))
        << "\n";
    for (const auto& f : info.formulations) {
      out << "    formulation " << f.name << ": " << f.description << "\n";
      for (const auto& c : f.constraints)
        out << "      constraint " << c.name << " [" << c.kind << "]: " << c.description << "\n";
    }
    out << "    methods:";
    for (const auto& m : all_methods()) {
      const std::string why = p->why_not(m.name);
      out << " " << m.name << (why.empty() ? "" : " (n/a: " + why + ")");
    }
    out << "\n";
  }
  out << "METHODS\n";
  for (const auto& m : all_methods()) {
    out << "  " << m.name << ": " << m.description << "\n";
    for (const auto& s : m.params)
      out << "    --param " << s.name << "=" << format_short(s.default_value) << "  (" << bound_text(s.bound)
          << ") " << s.description << "\n";
  }
  out << "INTEGRATORS\n";
  for (const auto& i : all_integrators())
    out << "  " << i.name << ": " << i.description << (i.fixed_step ? "  [--step]" : "  [--rtol --atol]")
        << "\n";
  std::cout << out.str();
  return 0;
}

int cmd_run(const std::vector<std::string>& argv) {
  Args args(argv,
            {"--problem", "--method", "--formulation", "--param", "--integrator", "--step", "--rtol", "--atol",
             "--t-end", "--times", "--sample-every", "--ref-time", "--blowup", "--observe-every", "--out",
             "--perturb", "--recovery-threshold", "--drift-fit-from"},
            {"--no-series"}, {"--param", "--times"});
  if (!args.positional().empty()) throw UsageError("run: unexpected argument '" + args.positional()[0] + "'");
  RunConfig cfg;
  cfg.problem = args.require("--problem");
  cfg.method = args.require("--method");
  cfg.formulation = args.get("--formulation");
  cfg.integrator = args.require("--integrator");
  const Problem& problem = find_problem(cfg.problem);
  const IntegratorInfo& integ = find_integrator(cfg.integrator);
  for (const auto& kv : args.all("--param")) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--param " + kv + ": expected name=value");
    cfg.params.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
  }
  if (integ.fixed_step) {
    if (args.has("--rtol") || args.has("--atol"))
      throw UsageError("--rtol/--atol: integrator '" + integ.name + "' is fixed-step; give --step");
    cfg.step.step = parse_finite_double(args.require("--step"), "--step");
  } else {
    if (args.has("--step")) throw UsageError("--step: integrator '" + integ.name + "' is adaptive; give --rtol and --atol");
    cfg.step.rtol = parse_finite_double(args.require("--rtol"), "--rtol");
    cfg.step.atol = parse_finite_double(args.require("--atol"), "--atol");
  }
  cfg.t_end = parse_finite_double(args.require("--t-end"), "--t-end");
  cfg.times = args.number_list("--times");
  cfg.sample_every = args.number("--sample-every", 0);
  cfg.ref_time = args.number("--ref-time", -1);
  if (args.has("--ref-time") && !(cfg.ref_time >= 0 && cfg.ref_time <= cfg.t_end))
    throw UsageError("--ref-time: must be in [0, t_end] (0: no reference error)");
  cfg.blowup = args.number("--blowup", 1e3);
  const long observe_every = args.integer("--observe-every", 1);
  if (observe_every < 1 || observe_every > 1000000000) throw UsageError("--observe-every: must be in [1, 1e9]");
  cfg.observe_every = int(observe_every);
  cfg.write_series = !args.has("--no-series");
  cfg.perturb = args.number("--perturb", 0);
  cfg.recovery_threshold = args.number("--recovery-threshold", 1e-10);
  cfg.drift_fit_from = args.number("--drift-fit-from", 10);
  const std::string out = args.require("--out");

  const RunResult r = run_case(problem, cfg, out);
  std::cout << r.problem << " / " << r.formulation << " / " << r.method << " / " << r.integrator << ": "
            << r.status << (r.reason.empty() ? "" : " (" + r.reason + ")") << ", t = " << r.t_reached
            << ", steps " << r.steps << ", rhs " << r.rhs_evals << ", wall " << r.wall_seconds << " s"
            << ", max residual " << r.max_residual;
  if (r.has_energy) std::cout << ", max |dE| " << r.max_energy_drift;
  if (!std::isnan(r.ref_error)) std::cout << ", error at t=" << r.ref_time << " " << r.ref_error;
  std::cout << "\n  wrote " << out << "/summary.csv" << (cfg.write_series ? " and series.csv" : "") << "\n";
  return 0;
}

}  // namespace

int dispatch(const std::string& command, const std::vector<std::string>& args) {
  if (command == "list") return cmd_list(args);
  if (command == "run") return cmd_run(args);
  if (command == "stability") return cmd_stability(args);
  if (command == "matrix") return cmd_matrix(args);
  if (command == "merge") return cmd_merge(args);
  if (command == "report") return cmd_report(args);
  if (command == "gate") return cmd_gate(args);
  throw UsageError("unknown command '" + command + "' (known: list, run, stability, matrix, merge, report, gate)");
}

}  // namespace cstab::cli

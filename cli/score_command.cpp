// cstab score (declare_score lists the options; --help prints them): the
// metrics of `cstab run` for a trajectory computed elsewhere
// (harness/score.hpp; docs/score.md).

#include <cmath>
#include <iostream>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/format.hpp"
#include "harness/score.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

void declare_score(Args& a) {
  const ScoreConfig d;
  a.required("--problem", "NAME", "the problem the trajectory is of (cstab list)")
      .repeatable("--problem-param", "K=V", "the problem's parameters, as for run")
      .value("--formulation", "NAME", "must be the formulation whose state is the canonical coordinates (the default)")
      .value("--label", "NAME", "the summary's method column", d.label)
      .value("--ref-time", "T", "time of the error against the reference; 0: none (default: the problem's, if within the trajectory)")
      .value("--wall-seconds", "S", "the producer's wall time (else a '# wall_seconds = S' line of the file; else none)")
      .value("--sample-every", "DT", "one series row per DT of time (0: span/1000)", format_short(d.sample_every))
      .value("--blowup", "B", "residual above which the trajectory is recorded as diverged", format_short(d.blowup))
      .value("--recovery-threshold", "R", "residual the trajectory must return to and stay below",
             format_short(d.recovery_threshold))
      .value("--drift-fit-from", "T", "fit the drift growth exponent over [T, t_end] (if t_end >= 4 T; 0: no fit)",
             format_short(d.drift_fit_from))
      .flag("--no-series", "write summary.csv only, no series.csv")
      .positional("TRAJECTORY", "CSV (or .csv.gz): t and the problem's coordinates (cstab list), one row per time",
                  true)
      .required("--out", "DIR", "output folder (created if missing)");
}

int cmd_score(const Args& args) {
  ScoreConfig cfg;
  cfg.problem = args.require("--problem");
  cfg.problem_params = args.pairs("--problem-param");
  cfg.formulation = args.get("--formulation");
  cfg.label = args.get("--label");
  if (args.has("--ref-time")) {
    cfg.ref_time = args.number("--ref-time");
    if (!(cfg.ref_time >= 0)) throw UsageError("--ref-time: must be >= 0 (0: no reference error)");
  }
  if (args.has("--wall-seconds")) cfg.wall_seconds = args.number("--wall-seconds");
  cfg.sample_every = args.number("--sample-every");
  cfg.blowup = args.number("--blowup");
  cfg.recovery_threshold = args.number("--recovery-threshold");
  cfg.drift_fit_from = args.number("--drift-fit-from");
  cfg.write_series = !args.has("--no-series");
  const std::string path = args.require("TRAJECTORY");
  const std::string out = args.require("--out");
  const Problem& problem = find_problem(cfg.problem);

  const RunResult r = score_trajectory(problem, cfg, path, out);
  std::cout << r.problem << (r.problem_params.empty() ? "" : " (" + r.problem_params + ")") << " / "
            << r.formulation << " / " << r.method << ": " << r.status
            << (r.reason.empty() ? "" : " (" + r.reason + ")") << ", t = " << r.t_reached << ", rows "
            << r.steps + 1 << ", max residual " << r.max_residual;
  if (r.has_energy) std::cout << ", max |dE| " << r.max_energy_drift;
  if (!std::isnan(r.ref_error)) std::cout << ", error at t=" << r.ref_time << " " << r.ref_error;
  if (!std::isnan(r.wall_seconds)) std::cout << ", wall " << r.wall_seconds << " s";
  std::cout << "\n";
  for (const auto& [name, value] : r.extra)
    if (name == "differenced" && value != "none")
      std::cout << "  velocities differenced from positions (second order): " << value << "\n";
  std::cout << "  wrote " << out << "/summary.csv" << (cfg.write_series ? " and series.csv" : "") << "\n";
  return 0;
}

}  // namespace cstab::cli

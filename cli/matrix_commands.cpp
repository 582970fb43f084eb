#include "cli/matrix_commands.hpp"

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <map>
#include <iostream>
#include <thread>

#include "cli/args.hpp"
#include "io/csv.hpp"
#include "io/lock.hpp"
#include "matrix/matrix.hpp"
#include "matrix/provenance.hpp"
#include "report/report.hpp"
#include "methods/pair.hpp"
#include "plugin/loader.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

namespace {

// The default matrix. "all" expands at run time, so problems and methods
// added to the registries join it without an edit here. Budget: <= 10 min
// with --jobs 2 on a 2-core machine (README, docs/matrix.md).
const char* kDefaultMatrix = R"(# cstab default matrix (embedded; `cstab matrix --print-default` prints it).
# Every problem x every applicable method: a work-precision sweep per
# integrator family up to the problem's reference time, one long run per
# method for the time-series overlays, and the papers' own settings.
# Budget: <= 10 minutes with --jobs 2 on a 2-core machine.

[defaults]
problems = "all"
methods = "all"
t_end = "ref"          # the problem's reference time: the error against the reference is defined there
repeats = 3            # wall time = median of the repeats ...
repeat_if_under = 0.5  # ... for runs under 0.5 s; longer runs are timed once
timeout = 300          # a run that hangs is recorded as `timeout`, the matrix goes on
# n-four-bar (IFToMM A02) at N = 10 here, not its benchmark's 40: N only
# scales each step's cost (scripts/scaling.py measures N = 5 .. 320).
problem_param.n-four-bar.N = 10

# Fixed step, classical RK4 (Braun-Goldfarb's integrator), coarse to fine.
[[sweep]]
name = "wp-rk4"
integrators = ["rk4"]
step = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]

# Fixed step, Adams-Bashforth-Moulton PECE (Pesterev et al.'s integrator).
[[sweep]]
name = "wp-adams"
integrators = ["adams"]
step = [1e-3, 3e-4, 1e-4, 3e-5]

# Adaptive Prince-Dormand 8(9), rtol = atol = tol. Braun-Goldfarb's
# correction time scale is the step of a fixed-step integrator; here 1 ms.
[[sweep]]
name = "wp-rk8pd"
integrators = ["rk8pd"]
tol = [1e-6, 1e-8, 1e-10, 1e-12]
param.braun-goldfarb.dt = 1e-3
# At most 3e5 steps (the stiff flyball governor takes 7.2e4 at 1e-12): near
# n-four-bar's singular positions the error control can crawl (4.3e6 steps
# in 191 s, post-stabilization at 1e-10), recorded as failed at the limit.
max_steps = 3e5

# DAE formulations on SUNDIALS IDA (variable-order BDF).
[[sweep]]
name = "wp-ida"
methods = ["ida-index1", "ida-ggl"]
integrators = ["ida"]
tol = [1e-6, 1e-8, 1e-10]
optional = true

# SUNDIALS ODE integrators (docs/methods.md): ARKODE's explicit Fehlberg 8(7)
# on every method, CVODE's BDF on the methods without a post-step (a
# projection restarts it at order 1 after every step), the penalty
# formulation among them.
[[sweep]]
name = "wp-ark-erk"
integrators = ["ark-erk-fehlberg8"]
tol = [1e-6, 1e-9]
param.braun-goldfarb.dt = 1e-3
max_steps = 3e5

[[sweep]]
name = "wp-cvode-bdf"
methods = ["pesterev", "baumgarte", "penalty", "none", "minimal"]
integrators = ["cvode-bdf"]
tol = [1e-6, 1e-9]
max_steps = 3e5

# The generalized-alpha family, the augmented Lagrangian (ali3p), RATTLE
# (constant-mass holonomic problems) and the symmetric projection (holonomic
# problems): each method is its own fixed-step scheme (integrator "own");
# three steps keep it to seconds per problem.
[[sweep]]
name = "wp-own"
methods = ["generalized-alpha", "hht", "generalized-alpha-i2", "ali3p", "rattle", "symmetric-projection"]
integrators = ["own"]
step = [1e-2, 3e-3, 1e-3]

# The problem's own horizon, one setting for every method: residual and
# drift against time (the overlays).
[[sweep]]
name = "long"
integrators = ["rk4"]
step = 1e-3
t_end = "default"
repeats = 1
work_precision = false
overlay = true

[[sweep]]
name = "long-ida"
methods = ["ida-index1", "ida-ggl"]
integrators = ["ida"]
tol = 1e-8
t_end = "default"
repeats = 1
work_precision = false
overlay = true
optional = true

# Cost against size (the report's Scaling section): fekete at N = 5 .. 40,
# the band and the dense KKT solve (matrices/scaling.toml goes to N = 320).
[[sweep]]
name = "scaling"
problems = ["fekete"]
methods = ["projection"]
integrators = ["rk8pd"]
tol = [1e-6, 1e-8, 1e-10]
problem_param.N = [5, 10, 20, 40]
param.kkt = [0, 1]
work_precision = false

# Pesterev, Matrosov, Morozov: Adams, fixed step 1e-5, lambda = 1500, t in [0, 200].
[[sweep]]
name = "paper-pesterev"
problems = ["wheel"]
methods = ["pesterev"]
integrators = ["adams"]
step = 1e-5
t_end = 200
param.lambda = 1500
repeats = 1
work_precision = false
optional = true

# The IFToMM benchmark A01 (the pendulum): its 2000 s horizon, scored at the
# end (position within 1e-1 and 1e-3 of the reference: low and high precision).
[[sweep]]
name = "paper-iftomm-a01"
problems = ["pendulum"]
methods = ["minimal", "projection", "baumgarte"]
integrators = ["rk8pd"]
tol = [1e-6, 1e-8, 1e-10]
t_end = 2000
ref_time = 2000
repeats = 1
work_precision = false
optional = true

[[sweep]]
name = "paper-iftomm-a01-own"
problems = ["pendulum"]
methods = ["ali3p", "rattle"]
integrators = ["own"]
step = [1e-3, 1e-4]
t_end = 2000
ref_time = 2000
repeats = 1
work_precision = false
optional = true

# Braun, Goldfarb: RK4, dt = 1e-2, t in [0, 100].
[[sweep]]
name = "paper-braun-goldfarb"
problems = ["ball", "biped"]
methods = ["braun-goldfarb"]
integrators = ["rk4"]
step = 1e-2
t_end = 100
repeats = 1
work_precision = false
optional = true
)";

// The file's `plugins` (relative paths from the file's folder), loaded
// before it expands so that its sweeps may name what they add.
void load_matrix_plugins(const MatrixFile& file, const std::string& file_path) {
  const std::filesystem::path base = std::filesystem::path(file_path).parent_path();
  for (const std::string& p : matrix_plugins(file)) {
    const std::filesystem::path path(p);
    load_plugin(path.is_absolute() || base.empty() ? p : (base / path).string());
  }
}

MatrixCatalog registry_catalog() {
  MatrixCatalog catalog;
  for (const auto& p : all_problems()) catalog.problems.push_back(p.get());
  catalog.methods = all_methods();
  return catalog;
}

int default_jobs() { return std::max(1u, std::thread::hardware_concurrency()); }

void declare_jobs(Args& args, const std::string& what) {
  args.value("--jobs", "N", what + " at a time, in [1, 1024] (default: the number of cores)");
}

int jobs_flag(const Args& args) {
  const long jobs = args.has("--jobs") ? args.integer("--jobs") : default_jobs();
  if (jobs < 1 || jobs > 1024) throw UsageError("--jobs: must be in [1, 1024]");
  return int(jobs);
}

// --svg: the pictures as SVG too (by default PNG only; plots/replot.sh draws both).
void declare_svg(Args& args) {
  args.flag("--svg", "also draw every picture as SVG (plots/NAME.svg); by default only the PNGs are drawn");
}

// --svg, refused (exit 2) beside `other`, a flag under which no picture is drawn.
bool svg_flag(const Args& args, const std::string& other) {
  if (args.has("--svg") && args.has(other)) throw UsageError("--svg: draws the pictures; not with " + other);
  return args.has("--svg");
}

ReportResult finish(const std::string& dir, int jobs, bool plots, bool svg) {
  ReportOptions ro;
  ro.jobs = jobs;
  ro.plots = plots;
  ro.svg = svg;
  ReportResult r = build_report(dir, ro, std::cerr);
  std::cout << "report: " << r.html << " (" << r.plots_drawn << " plots drawn, " << r.plots_reused
            << " unchanged)\n";
  return r;
}

std::string one_decimal(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

// After the report: the series no picture reads go, the others are cut to
// the columns the pictures read at plot precision (each case stays cached),
// unless the case keeps them (keep_series, --keep-series).
void shrink_series_after(const std::string& out, const std::vector<MatrixCase>& cases, const ReportResult& report) {
  const SeriesShrunk d = shrink_series(out, cases, report.series_used);
  if (d.dropped)
    std::cout << "matrix: kept the series the pictures read; dropped " << d.dropped << " others ("
              << one_decimal(double(d.dropped_bytes) / 1e6) << " MB; --keep-series or keep_series = true keeps them)\n";
  if (d.reduced)
    std::cout << "matrix: cut the " << d.reduced << " series the pictures read to their columns and 7 digits ("
              << one_decimal(double(d.reduced_bytes_saved) / 1e6) << " MB less; --keep-series keeps them whole)\n";
}

// Outcomes over the whole folder, cached cases included: "3 ok, 1 diverged".
std::string folder_outcomes(const std::string& out) {
  std::map<std::string, size_t> outcomes;
  const CsvTable summary = read_csv(out + "/summary.csv");
  for (size_t r = 0; r < summary.rows.size(); ++r)
    if (summary.get(r, "repeat") == "0") ++outcomes[summary.get(r, "status")];
  std::string text;
  for (const auto& [status, n] : outcomes)
    text += (text.empty() ? "" : ", ") + std::to_string(n) + " " +
            (status == "invalid" ? std::string("not applicable") : status);
  return text.empty() ? "no results" : text;
}

// A run cut short: says so on stderr and returns the exit code; 0 if every
// case finished.
int unfinished_exit_code(const MatrixRunStats& stats, const std::string& out) {
  if (stats.interrupted_by) {
    // Finished cases are kept (and summarized); the report waits for a
    // complete run.
    std::cout.flush();
    std::cerr << "cstab matrix: interrupted by " << stop_signal_name(stats.interrupted_by) << ": "
              << stats.total - stats.unfinished << " of " << stats.total << " cases finished and kept in " << out
              << "/summary.csv, " << stats.unfinished << " unfinished; run the same command again to resume (exit "
              << 128 + stats.interrupted_by << ")\n";
    return 128 + stats.interrupted_by;
  }
  if (stats.infrastructure) {
    std::cout.flush();
    std::cerr << "cstab matrix: " << stats.infrastructure << " of " << stats.total
              << " cases not recorded (a worker crashed, was killed from outside or hit an I/O error; see above); "
                 "run the same command again to complete them (exit 1)\n";
    return 1;
  }
  if (stats.unfinished) {
    std::cout.flush();
    std::cerr << "cstab matrix: " << stats.unfinished << " of " << stats.total
              << " cases unfinished (their workers were stopped by a signal); run the same command again to "
                 "complete them (exit 1)\n";
    return 1;
  }
  return 0;
}

MatrixRunOptions matrix_run_options(const std::string& out, int jobs, bool force, const std::string& matrix_text,
                                    size_t selected_cases) {
  MatrixRunOptions opt;
  opt.out_dir = out;
  opt.jobs = jobs;
  opt.force = force;
  opt.binary_id = binary_identity();
  if (opt.binary_id == "unknown")
    std::cout << "matrix: note: the cstab binary cannot be read, so no result is reused or trusted as cached: "
                 "every case runs\n";
  opt.matrix_text = matrix_text;
  opt.selected_cases = selected_cases;
  opt.find_problem = [](const std::string& name) -> const Problem& { return find_problem(name); };
  return opt;
}

}  // namespace

const std::string& default_matrix_text() {
  static const std::string text = kDefaultMatrix;
  return text;
}

void declare_matrix(Args& a) {
  a.positional("FILE", "matrix file (docs/matrix.md); default: the embedded matrix (--print-default)", false)
      .value("--out", "DIR", "results folder (created; cases already in it are reused)");
  declare_jobs(a, "cases");
  a.value("--shard", "K/N", "run only shard K of N (join the shard folders with `cstab merge`)")
      .value("--filter", "S", "run only the cases whose label contains S, or whose id or sweep name is S (see --list)")
      .flag("--force", "rerun cases even if their results are in DIR")
      .flag("--no-report", "do not build the report after the run (every series is then kept)");
  declare_svg(a);
  a.flag("--keep-series", "keep every case's series whole (as matrix key keep_series = true); by default only "
                          "the series the report's pictures read are kept, cut to their columns and 7 digits")
      .flag("--list", "print the cases (index, id, sweep, label) and exit; no --out needed")
      .flag("--print-default", "print the embedded default matrix and exit");
}

int cmd_matrix(const Args& args) {
  if (args.has("--print-default")) {
    std::cout << default_matrix_text();
    return 0;
  }
  const bool from_file = args.has("FILE");
  const MatrixFile file = from_file ? read_matrix_file(args.get("FILE"))
                                    : parse_matrix(default_matrix_text(), "<default matrix>");
  load_matrix_plugins(file, from_file ? args.get("FILE") : "");
  const Expansion expansion = expand_matrix(file, registry_catalog());
  int shard_k = 1, shard_n = 1;
  if (args.has("--shard")) std::tie(shard_k, shard_n) = parse_shard(args.require("--shard"));
  const std::string filter = args.get("--filter");
  const auto filtered = select_cases(expansion.cases, filter, 1, 1);
  if (!filter.empty() && filtered.empty())
    throw UsageError("--filter '" + filter + "': matches none of the " + std::to_string(expansion.cases.size()) +
                     " cases (see --list)");
  auto cases = select_cases(filtered, "", shard_k, shard_n);
  const bool svg = svg_flag(args, "--no-report");
  if (svg && shard_n > 1) throw UsageError("--svg: a shard builds no report; give it to `cstab merge`");
  if (args.has("--keep-series"))
    for (auto& c : cases) c.keep_series = true;

  if (args.has("--list")) {
    for (const auto& n : expansion.notes) std::cout << "# note: " << n << "\n";
    for (const auto& c : cases)
      std::cout << c.entry.index << "\t" << c.entry.id << "\t" << c.entry.sweep << "\t" << c.entry.label() << "\n";
    return 0;
  }
  const std::string out = args.require("--out");
  const int jobs = jobs_flag(args);
  // The folder is ours until the end (report included); a second command
  // on it fails now, naming this one.
  const std::unique_ptr<FolderLock> lock =
      create_locked_folder(out, "cstab matrix", "--out " + out + ": cannot create folder");

  std::cout << "matrix: " << file.name << ": " << expansion.cases.size() << " cases";
  if (!filter.empty()) std::cout << ", " << filtered.size() << " match --filter '" << filter << "'";
  if (shard_n > 1) std::cout << ", shard " << shard_k << "/" << shard_n << " has " << cases.size();
  std::cout << "; " << jobs << " jobs; results in " << out << "\n";
  for (const auto& n : expansion.notes) std::cout << "  note: " << n << "\n";

  Provenance prov = collect_provenance();
  prov.emplace_back("matrix_file", file.name);
  prov.emplace_back("matrix_cases", std::to_string(expansion.cases.size()));
  prov.emplace_back("filter", filter);
  prov.emplace_back("shard", std::to_string(shard_k) + "/" + std::to_string(shard_n));
  prov.emplace_back("cases_in_folder", std::to_string(cases.size()));
  prov.emplace_back("jobs", std::to_string(jobs));
  write_file_atomic(out + "/provenance.txt", format_provenance(prov));

  const MatrixRunOptions opt = matrix_run_options(out, jobs, args.has("--force"), file.text, filtered.size());
  const bool tty = ::isatty(STDOUT_FILENO);
  const MatrixRunStats stats = run_matrix(cases, opt, std::cout, tty);
  write_matrix_summary(out, [&] {
    std::vector<CaseEntry> entries;
    for (const auto& c : cases) entries.push_back(c.entry);
    return entries;
  }());
  std::cout << "matrix: " << stats.total << " cases: " << stats.run << " run, " << stats.cached << " cached, in "
            << one_decimal(stats.seconds) << " s; " << folder_outcomes(out) << "; " << out << "/summary.csv\n";
  if (const int code = unfinished_exit_code(stats, out)) return code;
  if (shard_n > 1)
    std::cout << "matrix: shard " << shard_k << "/" << shard_n << " done; join the shards with `cstab merge OUT "
              << "SHARD_DIR...`\n";
  else if (!args.has("--no-report"))
    shrink_series_after(out, cases, finish(out, jobs, true, svg));
  return 0;
}

void declare_merge(Args& a) {
  a.positional("OUT", "folder for the merged results (created)", true)
      .positional("SHARD_DIR", "results folders of `cstab matrix --shard K/N` (at least one)", true, true);
  declare_jobs(a, "plots");
  a.flag("--no-report", "do not build the report of OUT");
  declare_svg(a);
}

int cmd_merge(const Args& args) {
  const std::string out = args.require("OUT");
  const std::vector<std::string> shards = args.all("SHARD_DIR");
  const int jobs = jobs_flag(args);  // before anything is written
  const bool svg = svg_flag(args, "--no-report");
  const size_t missing = merge_results(out, shards, std::cout);
  if (!args.has("--no-report")) finish(out, jobs, true, svg);
  if (missing) {
    std::cerr << "cstab merge: " << missing << " cases of the matrix are missing from the shards (exit code 3)\n";
    return 3;
  }
  return 0;
}

void declare_report(Args& a) {
  a.positional("DIR", "a matrix results folder (cstab matrix --out)", true);
  declare_jobs(a, "plots");
  a.flag("--no-plots", "tables and HTML only, no gnuplot");
  declare_svg(a);
}

int cmd_report(const Args& args) {
  const std::string dir = args.require("DIR");
  const int jobs = jobs_flag(args);
  const bool svg = svg_flag(args, "--no-plots");
  // A results folder has its cases; anything else is refused untouched.
  if (!std::filesystem::is_directory(dir)) throw UsageError(dir + ": no such results folder");
  if (!std::filesystem::is_directory(dir + "/cases"))
    throw UsageError(dir + ": not a matrix results folder (no cases/ folder); nothing written");
  const std::vector<CaseEntry> entries = read_results_manifest(dir);
  const FolderLock lock(dir, "cstab report");
  write_matrix_summary(dir, entries);
  finish(dir, jobs, !args.has("--no-plots"), svg);
  return 0;
}

}  // namespace cstab::cli

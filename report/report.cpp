#include "report/report.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "core/format.hpp"
#include "io/csv.hpp"
#include "io/gzip.hpp"
#include "io/hash.hpp"
#include "io/number.hpp"
#include "io/text.hpp"
#include "matrix/matrix.hpp"
#include "matrix/provenance.hpp"
#include "matrix/results.hpp"
#include "methods/pair.hpp"
#include "report/scaling.hpp"
#include "report/stress_report.hpp"

#ifndef CSTAB_SOURCE_ROOT
#define CSTAB_SOURCE_ROOT ""
#endif

namespace cstab {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Short human form: 3 significant digits.
std::string sci(double v) { return format_3g(v); }

std::string seconds_text(double s) {
  if (std::isnan(s)) return "";
  char buf[32];
  if (s < 1e-3)
    std::snprintf(buf, sizeof buf, "%.3g \u00b5s", s * 1e6);
  else if (s < 1)
    std::snprintf(buf, sizeof buf, "%.3g ms", s * 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.3g s", s);
  return buf;
}

// A finished case with a timing: a point of the work-precision pictures and tables.
bool timed(const CaseResult& c) { return c.ok() && std::isfinite(c.wall_median); }

// Step size, else relative tolerance: coarse -> fine ordering.
double case_size(const CaseResult& c) { return std::isnan(c.step) ? c.rtol : c.step; }

// ---------------------------------------------------------------------------

struct Measure {
  const char* key;    // column in work_precision.csv
  const char* title;  // for the report
  double CaseResult::*value;
};
const std::array<Measure, 3> kMeasures = {{
    {"ref_error", "error against the reference", &CaseResult::ref_error},
    {"max_residual", "largest constraint residual", &CaseResult::max_residual},
    {"max_drift", "largest energy / first-integral drift", &CaseResult::drift},
}};

// A case of another engine: an external case of a matrix (matrix/external.hpp).
bool other_engine(const CaseResult& c) { return c.entry->integrator == "external"; }

// The engine of an external curve: its name up to the first '-'
// ("simbody-rkmerson" -> "simbody"), as matrices/peers.toml names them.
std::string engine_of(const CaseResult& c) { return c.entry->method.substr(0, c.entry->method.find('-')); }

// A case of a method that promises to stabilize (its conformance settings;
// for a method this build does not know, any but the constraint-free
// baselines none and minimal).
bool stabilizing(const CaseResult& c) {
  for (const MethodInfo& m : all_methods())
    if (m.name == c.entry->method) return m.conformance.stabilizes && m.name != "minimal";
  return c.entry->method != "none" && c.entry->method != "minimal";
}

// What a curve is in the rankings: a stabilization method (ranked), a limit
// (a constraint-free baseline of cstab: the minimal-coordinate ODE, none, a
// plugin that does not stabilize; shown apart, each method's time a
// multiple of it), or another engine (an external case).
enum class Role { kMethod, kLimit, kEngine };
Role role_of(const CaseResult& c) {
  if (other_engine(c)) return Role::kEngine;
  return stabilizing(c) ? Role::kMethod : Role::kLimit;
}
const char* role_name(Role r) {
  switch (r) {
    case Role::kMethod: return "method";
    case Role::kLimit: return "limit";
    case Role::kEngine: return "engine";
  }
  return "";
}

// Curves of role `role` reaching `level` in `measure`, each with its fastest such case, fastest first.
std::vector<const CaseResult*> rank_at(const std::vector<const CaseResult*>& cases, const Measure& m, double level,
                                       Role role = Role::kMethod) {
  std::map<std::string, const CaseResult*> best;
  for (const CaseResult* c : cases) {
    const double v = c->*(m.value);
    if (!timed(*c) || !(v <= level) || role_of(*c) != role) continue;
    auto& slot = best[c->entry->curve];
    if (!slot || c->wall_median < slot->wall_median) slot = c;
  }
  std::vector<const CaseResult*> out;
  for (const auto& [curve, c] : best) out.push_back(c);
  std::sort(out.begin(), out.end(), [](const CaseResult* a, const CaseResult* b) {
    return a->wall_median != b->wall_median ? a->wall_median < b->wall_median : a->entry->index < b->entry->index;
  });
  return out;
}

struct ProblemView {
  std::string name;
  std::vector<const CaseResult*> cases;     // all, expansion order
  std::vector<const CaseResult*> wp;        // work-precision cases
  std::vector<std::string> curves;          // wp curves, first-appearance order
  std::vector<std::string> methods, integrators;   // first-appearance order: colours, point types
  std::string drift_name;
  double ref_time = kNaN;
  std::vector<std::string> plots;           // basenames under DIR/plots
};

struct PlotJob {
  std::string name;    // basename, e.g. wheel_work_precision
  std::string script;  // file name in the scripts folder
  std::string vars;    // gnuplot -e text
  std::string data;    // data file contents (for the stamp)
  std::string caption;
};

std::string case_setting(const CaseResult& c) {
  std::string s = c.entry->setting;
  if (!c.entry->params.empty()) s += " " + c.entry->params;
  return s;
}

bool has_series(const std::string& dir, const CaseResult* c) {
  return c->complete && !case_series_path(dir, *c->entry).empty();
}

// Overlay run per method: the first overlay-marked case that finished
// (status ok), else the finished case with the longest horizon (smallest
// reference error among those), else the first overlay-marked case at all
// (a diverged run shows how it diverged).
std::vector<const CaseResult*> overlay_runs(const std::string& dir, const ProblemView& p) {
  std::vector<const CaseResult*> out;
  for (const auto& m : p.methods) {
    const CaseResult* pick = nullptr;
    for (const CaseResult* c : p.cases)
      if (!pick && c->entry->method == m && c->entry->overlay && timed(*c) && has_series(dir, c)) pick = c;
    if (!pick)
      for (const CaseResult* c : p.cases) {
        if (c->entry->method != m || !timed(*c) || !has_series(dir, c)) continue;
        if (!pick || c->entry->t_end > pick->entry->t_end ||
            (c->entry->t_end == pick->entry->t_end && (std::isnan(pick->ref_error) || c->ref_error < pick->ref_error)))
          pick = c;
      }
    if (!pick)
      for (const CaseResult* c : p.cases)
        if (!pick && c->entry->method == m && c->entry->overlay && has_series(dir, c)) pick = c;
    if (pick) out.push_back(pick);
  }
  return out;
}

// Trajectory run per method: its most accurate finished case against the
// reference (a short horizon, finely sampled, where the methods still
// agree); without a reference, its overlay run.
std::vector<const CaseResult*> trajectory_runs(const std::string& dir, const ProblemView& p,
                                               const std::vector<const CaseResult*>& overlay) {
  std::vector<const CaseResult*> out;
  for (const auto& m : p.methods) {
    const CaseResult* pick = nullptr;
    for (const CaseResult* c : p.cases)
      if (c->entry->method == m && timed(*c) && std::isfinite(c->ref_error) && has_series(dir, c) &&
          (!pick || c->ref_error < pick->ref_error))
        pick = c;
    if (!pick)
      for (const CaseResult* c : overlay)
        if (c->entry->method == m) pick = c;
    if (pick) out.push_back(pick);
  }
  return out;
}

std::string run_label(const CaseResult& c) {
  std::string s = c.entry->method + "/" + c.entry->integrator + " " + c.entry->setting;
  if (!c.entry->params.empty()) s += " " + c.entry->params;
  if (c.status != Status::kOk) s += std::string(" (") + status_name(c.status) + ")";
  return s;
}

std::string quoted_header(const std::string& label, const std::vector<std::string>& rest) {
  std::string h = gnuplot_data_title(label);
  for (const auto& r : rest) h += " " + r;
  return h + "\n";
}

// Series columns of a case, classified by name (header written by run_case).
struct SeriesColumns {
  std::vector<int> coords, residuals, drifts;  // drifts: energy if present, else first integrals
};
SeriesColumns classify(const CsvTable& s) {
  SeriesColumns c;
  std::vector<int> integrals;
  int energy = -1;
  bool in_coords = true;
  for (size_t i = 1; i < s.header.size(); ++i) {
    const std::string& h = s.header[i];
    const bool drift = h.size() > 6 && h.compare(h.size() - 6, 6, "_drift") == 0;
    if (h.rfind("residual_", 0) == 0) {
      c.residuals.push_back(int(i));
    } else if (h == "energy_drift") {
      energy = int(i);
    } else if (drift) {
      integrals.push_back(int(i));
    } else if (in_coords && h != "cond") {
      c.coords.push_back(int(i));
      continue;
    }
    in_coords = false;
  }
  c.drifts = energy >= 0 ? std::vector<int>{energy} : integrals;
  return c;
}

double cell(const std::vector<std::string>& row, int col) {
  return size_t(col) < row.size() ? parse_number(row[col]) : kNaN;
}

// A case's series (series.csv.gz or series.csv); empty if it is missing or unreadable.
CsvTable read_series(const std::string& dir, const CaseResult& c) { return load_case_series(dir, *c.entry); }

// Records that the pictures read columns `cols` of case `c`'s series `s`.
void note_use(SeriesUse& used, const CaseResult& c, const CsvTable& s, const std::vector<int>& cols) {
  for (int col : cols) used[c.entry->id].insert(s.header[col]);
}

// Overlay data: per run, t, max |residual|, |drift|. Colours in `lcs`; the
// columns read in `used`.
std::string overlay_data(const std::string& dir, const std::vector<const CaseResult*>& runs,
                         const std::map<std::string, int>& colour, std::string& lcs, bool& has_drift,
                         SeriesUse& used) {
  std::string out;
  has_drift = false;
  for (const CaseResult* c : runs) {
    const CsvTable s = read_series(dir, *c);
    if (s.rows.empty()) continue;  // missing or unreadable: the run is left out
    const SeriesColumns cols = classify(s);
    note_use(used, *c, s, cols.residuals);
    note_use(used, *c, s, cols.drifts);
    has_drift = has_drift || !cols.drifts.empty();
    if (!out.empty()) out += "\n\n";
    out += quoted_header(run_label(*c), {"max_abs_residual", "abs_drift"});
    lcs += " " + std::to_string(colour.at(c->entry->method));
    for (const auto& row : s.rows) {
      double res = cols.residuals.empty() ? kNaN : 0.0, drift = cols.drifts.empty() ? kNaN : 0.0;
      for (int col : cols.residuals) res = std::max(res, std::abs(cell(row, col)));
      for (int col : cols.drifts) drift = std::max(drift, std::abs(cell(row, col)));
      out += plot_cell(cell(row, 0)) + " " + log_plot_cell(res) + " " + log_plot_cell(drift) + "\n";
    }
  }
  return out;
}

// Trajectory data: per run, t and the position coordinates (names not
// ending in "dot"; at most 9). Colours in `lcs`, coordinate names in
// `names`, the columns read in `used`.
std::string trajectory_data(const std::string& dir, const std::vector<const CaseResult*>& runs,
                            const std::map<std::string, int>& colour, std::string& lcs,
                            std::vector<std::string>& names, SeriesUse& used) {
  std::string out;
  for (const CaseResult* c : runs) {
    const CsvTable s = read_series(dir, *c);
    if (s.rows.empty()) continue;  // missing or unreadable: the run is left out
    const SeriesColumns cols = classify(s);
    std::vector<int> shown;
    for (int col : cols.coords) {
      const std::string& h = s.header[col];
      if (h.size() < 3 || h.compare(h.size() - 3, 3, "dot") != 0) shown.push_back(col);
    }
    if (shown.empty()) shown = cols.coords;
    if (shown.size() > 9) shown.resize(9);
    note_use(used, *c, s, shown);
    std::vector<std::string> these;
    for (int col : shown) these.push_back(s.header[col]);
    if (out.empty()) names = these;
    if (these != names) continue;  // every block has the same columns
    if (!out.empty()) out += "\n\n";
    out += quoted_header(run_label(*c), names);
    lcs += " " + std::to_string(colour.at(c->entry->method));
    for (const auto& row : s.rows) {
      out += plot_cell(cell(row, 0));
      for (int col : shown) {
        const double v = cell(row, col);
        out += ' ';
        out += plot_cell(v);
      }
      out += "\n";
    }
  }
  return out;
}

// Starts gnuplot on `job` (output and errors to plots/data/NAME.log), PNG
// only or PNG and SVG (opt.svg); the child's pid, < 0 if it cannot start.
pid_t start_gnuplot(const PlotJob& job, const std::string& scripts, const std::string& plot_dir,
                    const ReportOptions& opt) {
  const std::string script = scripts + "/" + job.script;
  const std::string vars = job.vars + "; formats=" + gnuplot_string(opt.svg ? "png svg" : "png");
  const std::string log_path = plot_dir + "/data/" + job.name + ".log";
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::FILE* log = std::fopen(log_path.c_str(), "w");
    if (log) {
      ::dup2(::fileno(log), 1);
      ::dup2(::fileno(log), 2);
    }
    ::execlp("gnuplot", "gnuplot", "-e", vars.c_str(), script.c_str(), (char*)nullptr);
    ::_exit(127);
  }
  return pid;
}

// Runs the jobs, `opt.jobs` gnuplot processes at a time; returns failures.
// A failed job's picture files go (an empty or partial PNG is no picture).
std::vector<std::string> run_gnuplot(const std::vector<PlotJob>& todo, const std::string& scripts,
                                     const std::string& plot_dir, const ReportOptions& opt,
                                     std::set<std::string>& drawn) {
  std::vector<std::string> failures;
  std::map<pid_t, const PlotJob*> running;
  size_t next = 0;
  while (next < todo.size() || !running.empty()) {
    while (running.size() < size_t(std::max(1, opt.jobs)) && next < todo.size()) {
      const PlotJob& job = todo[next++];
      const pid_t pid = start_gnuplot(job, scripts, plot_dir, opt);
      if (pid < 0)
        failures.push_back(job.name + ": cannot start gnuplot");
      else
        running[pid] = &job;
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) break;
    auto it = running.find(pid);
    if (it == running.end()) continue;
    const PlotJob& job = *it->second;
    running.erase(it);
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::exists(plot_dir + "/" + job.name + ".png");
    if (ok) {
      drawn.insert(job.name);
      continue;
    }
    std::error_code ec;
    for (const char* ext : {".png", ".svg"}) fs::remove(plot_dir + "/" + job.name + ext, ec);
    const char* why = WIFEXITED(status) && WEXITSTATUS(status) == 127 ? "gnuplot not found" : "gnuplot failed";
    failures.push_back(job.name + ": " + why + " (see " + plot_dir + "/data/" + job.name + ".log)");
  }
  return failures;
}

std::string file_or_empty(const std::string& path) {
  try {
    return read_text_file(path);
  } catch (const std::exception&) {
    return "";
  }
}

const char* kStyle = R"(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; margin: 0 auto; max-width: 1480px; padding: 0 24px 48px; color: #1d1d1f; }
h1 { font-size: 26px; margin: 24px 0 4px; }
h2 { font-size: 21px; margin-top: 40px; border-bottom: 2px solid #0072B2; padding-bottom: 4px; }
h3 { font-size: 16px; margin: 22px 0 8px; }
p.meta { color: #555; margin-top: 2px; }
table { border-collapse: collapse; font-size: 13px; margin: 8px 0 16px; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #eef3f8; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.bad td { background: #fdecea; }
tr.div td { background: #fff6e0; }
img { max-width: 100%; border: 1px solid #ddd; display: block; margin: 6px 0 2px; }
figure { margin: 12px 0 24px; }
figcaption { font-size: 13px; color: #444; }
nav a { margin-right: 14px; }
details summary { cursor: pointer; font-weight: bold; margin: 8px 0; }
pre { background: #f6f8fa; padding: 10px; font-size: 12px; overflow-x: auto; }
.win { font-weight: bold; color: #006d3a; }
div.wide { overflow-x: auto; max-width: 100%; }
td.reason { max-width: 360px; font-size: 12px; color: #444; }
)";

}  // namespace

const std::vector<double>& accuracy_levels() {
  static const std::vector<double> levels = {1e-4, 1e-6, 1e-8, 1e-10, 1e-12};
  return levels;
}

std::string find_plot_scripts() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("CSTAB_PLOTS")) candidates.push_back(env);
  if (*CSTAB_SOURCE_ROOT) candidates.push_back(std::string(CSTAB_SOURCE_ROOT) + "/plots");
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back((exe.parent_path() / "../../../plots").lexically_normal().string());
  if (!ec) candidates.push_back((exe.parent_path() / "../share/cstab/plots").lexically_normal().string());
  for (const auto& c : candidates)
    if (fs::exists(c + "/work_precision.gp")) return c;
  return "";
}


namespace {

// ---- stages of build_report ----

// The folder parsed once; DIR/summary.csv written first if it is missing.
ResultsFolder load_report_input(const std::string& dir) {
  ResultsFolder folder = load_results_folder(dir);
  if (!fs::exists(dir + "/summary.csv")) write_matrix_summary(dir, folder.entries);
  return folder;
}

// Cases grouped by problem (first-appearance order), with the curves, methods and integrators of each.
std::vector<ProblemView> group_by_problem(const std::vector<CaseResult>& results) {
  std::vector<ProblemView> problems;
  auto add_once = [](std::vector<std::string>& list, const std::string& s) {
    if (std::find(list.begin(), list.end(), s) == list.end()) list.push_back(s);
  };
  for (const CaseResult& c : results) {
    auto it = std::find_if(problems.begin(), problems.end(), [&](const ProblemView& p) { return p.name == c.entry->problem; });
    if (it == problems.end()) {
      problems.push_back({});
      problems.back().name = c.entry->problem;
      it = problems.end() - 1;
    }
    it->cases.push_back(&c);
    add_once(it->methods, c.entry->method);
    add_once(it->integrators, c.entry->integrator);
    if (c.entry->work_precision) {
      it->wp.push_back(&c);
      add_once(it->curves, c.entry->curve);
    }
    if (it->drift_name.empty()) it->drift_name = c.drift_name;
    if (std::isnan(it->ref_time) && timed(c)) it->ref_time = c.ref_time;
  }
  return problems;
}

// DIR/work_precision.csv: one row per work-precision case.
void write_work_precision_csv(const std::string& dir, const std::vector<ProblemView>& problems) {
  std::string csv =
      "problem,curve,method,formulation,integrator,params,setting,step,rtol,atol,t_end,case_id,sweep,repeats,"
      "status,wall_median_s,wall_min_s,wall_max_s,steps,rhs_evals,ref_time,ref_error,ref_scd,max_residual,"
      "drift_quantity,max_drift\n";
  for (const auto& p : problems)
    for (const CaseResult* c : p.wp) {
      const CaseEntry& e = *c->entry;
      csv += csv_line({e.problem, e.curve, e.method, c->formulation, e.integrator, e.params, e.setting,
                       number_cell(c->step), number_cell(c->rtol), number_cell(c->atol), format_short(e.t_end), e.id,
                       e.sweep, std::to_string(e.repeats), status_name(c->status), number_cell(c->wall_median),
                       number_cell(c->wall_min), number_cell(c->wall_max), count_cell(c->steps),
                       count_cell(c->rhs_evals), number_cell(c->ref_time), number_cell(c->ref_error),
                       number_cell(c->ref_scd), number_cell(c->max_residual), c->drift_name, number_cell(c->drift)});
    }
  write_file_atomic(dir + "/work_precision.csv", csv);
}

// DIR/fastest.csv: per problem, measure and level, the curves reaching it, fastest first.
void write_fastest_csv(const std::string& dir, const std::vector<ProblemView>& problems) {
  std::string fast =
      "problem,measure,threshold,role,rank,curve,method,integrator,case_id,setting,wall_median_s,value,"
      "ratio_to_fastest,ratio_to_limit\n";
  for (const auto& p : problems)
    for (const Measure& m : kMeasures)
      for (double level : accuracy_levels()) {
        const auto methods = rank_at(p.wp, m, level, Role::kMethod);
        const auto limits = rank_at(p.wp, m, level, Role::kLimit);
        // Ratios to the fastest stabilization method and to the fastest limit.
        const double fastest = methods.empty() ? kNaN : methods[0]->wall_median;
        const double limit = limits.empty() ? kNaN : limits[0]->wall_median;
        for (Role role : {Role::kMethod, Role::kLimit, Role::kEngine}) {
          const auto ranked = role == Role::kMethod ? methods : role == Role::kLimit ? limits : rank_at(p.wp, m, level, role);
          for (size_t r = 0; r < ranked.size(); ++r) {
            const CaseResult& c = *ranked[r];
            fast += csv_line({p.name, m.key, format_short(level), role_name(role), std::to_string(r + 1),
                              c.entry->curve, c.entry->method, c.entry->integrator, c.entry->id, case_setting(c),
                              number_cell(c.wall_median), number_cell(c.*(m.value)),
                              number_cell(c.wall_median / fastest), number_cell(c.wall_median / limit)});
          }
        }
      }
  write_file_atomic(dir + "/fastest.csv", fast);
}

// The pictures to draw: data files written as jobs are added.
struct PlotSet {
  std::string plot_dir;
  std::vector<PlotJob> jobs;
  std::map<std::string, std::string> captions;
  SeriesUse series_used;  // the series the pictures read: case id -> columns
  // Writes plots/data/<name>.dat.gz (gzip, read by the scripts through
  // gzip -dc; style.gp) and queues the job; returns the name.
  std::string add(const std::string& name, const std::string& script, const std::string& data,
                  const std::string& extra_vars, const std::string& caption) {
    const std::string data_path = plot_dir + "/data/" + name + ".dat.gz";
    write_file_atomic(data_path, gzip_compress(data));
    std::error_code ec;
    fs::remove(plot_dir + "/data/" + name + ".dat", ec);  // plain, from cstab before issue 16
    jobs.push_back({name, script,
                    "data=" + gnuplot_string(data_path) + "; out=" + gnuplot_string(plot_dir + "/" + name) + extra_vars,
                    data, caption});
    captions[name] = caption;
    return name;
  }
};

// Colour = method, point type and dash = integrator, the same in every picture of a problem.
struct ProblemStyle {
  const ProblemView& p;
  std::map<std::string, int> colour;
  explicit ProblemStyle(const ProblemView& view) : p(view) {
    for (size_t i = 0; i < p.methods.size(); ++i) colour[p.methods[i]] = int(i % 12) + 1;
  }
  std::pair<int, int> integrator(const std::string& name) const {
    static const int points[] = {7, 5, 9, 11, 13, 15, 4, 6, 8, 10};
    const size_t j = size_t(std::find(p.integrators.begin(), p.integrators.end(), name) - p.integrators.begin());
    return {points[j % 10], int(j % 5) + 1};
  }
};

// Work-precision data: one block per curve, coarse to fine, with its styles;
// cstab's curves first, then other engines' (external cases), which the
// picture draws with their own point and dash under the key's "other
// engines" heading.
// A tuned curve's envelope (key `tune`): of its cases (every gain x every
// step or tolerance), those that no faster case beats in error against the
// reference (in the largest residual where no case has a reference error),
// fastest first: the best gain at each cost.
std::vector<const CaseResult*> tuned_envelope(std::vector<const CaseResult*> cases,
                                              const std::vector<const CaseResult*>& all) {
  const bool by_ref = std::any_of(all.begin(), all.end(), [](const CaseResult* c) { return std::isfinite(c->ref_error); });
  auto error = [&](const CaseResult* c) {
    const double v = by_ref ? c->ref_error : c->max_residual;
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };
  std::stable_sort(cases.begin(), cases.end(),
                   [](const CaseResult* a, const CaseResult* b) { return a->wall_median < b->wall_median; });
  std::vector<const CaseResult*> out;
  for (const CaseResult* c : cases)
    if (out.empty() ? std::isfinite(error(c)) : error(c) < error(out.back())) out.push_back(c);
  return out;
}

struct WorkPrecisionData {
  std::string text, lcs, pts, dts;
  size_t blocks = 0, cstab_blocks = 0;
  bool has_ref = false, has_drift = false;
};
WorkPrecisionData work_precision_data(const ProblemView& p, const ProblemStyle& style) {
  WorkPrecisionData d;
  for (int pass = 0; pass < 2; ++pass)
  for (const auto& curve : p.curves) {
    std::vector<const CaseResult*> pts_of;
    for (const CaseResult* c : p.wp)
      if (c->entry->curve == curve && timed(*c) && other_engine(*c) == (pass == 1)) pts_of.push_back(c);
    if (pts_of.empty()) continue;
    if (pass == 0) ++d.cstab_blocks;
    std::stable_sort(pts_of.begin(), pts_of.end(), [](const CaseResult* a, const CaseResult* b) {
      return a->entry->t_end != b->entry->t_end ? a->entry->t_end < b->entry->t_end : case_size(*a) > case_size(*b);
    });
    const bool tuned = pts_of[0]->entry->tuned();
    if (tuned) pts_of = tuned_envelope(pts_of, p.wp);
    if (d.blocks++) d.text += "\n\n";
    d.text += quoted_header(curve, {"wall_median_s", "ref_error", "ref_scd", "max_residual", "max_drift", "setting"});
    auto [point, dash] = style.integrator(pts_of[0]->entry->integrator);
    if (pass == 1) point = 3, dash = 4;  // other engines: asterisks, dash-dot
    // A tuned envelope: the open form of its integrator's point (x if it has none).
    if (tuned) point = point % 2 == 1 && point >= 5 ? point - 1 : 2;
    d.lcs += " " + std::to_string(style.colour.at(pts_of[0]->entry->method));
    d.pts += " " + std::to_string(point);
    d.dts += " " + std::to_string(dash);
    for (const CaseResult* c : pts_of) {
      d.has_ref = d.has_ref || (std::isfinite(c->ref_error) && c->ref_error > 0);
      d.has_drift = d.has_drift || (std::isfinite(c->drift) && c->drift > 0);
    }
    for (const CaseResult* c : pts_of)
      d.text += plot_cell(c->wall_median) + " " + log_plot_cell(c->ref_error) + " " + plot_cell(c->ref_scd) + " " +
                log_plot_cell(c->max_residual) + " " + log_plot_cell(c->drift) + " " + plot_cell(case_size(*c)) + "\n";
  }
  return d;
}

// <problem>_work_precision: error against wall time, one curve per method/integrator.
void add_work_precision_plot(PlotSet& plots, ProblemView& p, const ProblemStyle& style) {
  const WorkPrecisionData d = work_precision_data(p, style);
  if (!d.blocks) return;
  const std::string drift_label =
      p.drift_name == "energy" ? "max |E(t) - E(0)|"
                               : (p.drift_name.empty() ? "max drift (no energy law or first integral)"
                                                       : "max drift of " + p.drift_name);
  const std::string ref_label = std::isnan(p.ref_time) ? "the reference time" : "t = " + format_short(p.ref_time);
  p.plots.push_back(plots.add(
      p.name + "_work_precision", "work_precision.gp", d.text,
      "; problem=" + gnuplot_string(p.name) + "; has_ref=" + std::string(d.has_ref ? "1" : "0") +
          "; has_drift=" + (d.has_drift ? "1" : "0") + "; drift_label=" + gnuplot_string(drift_label) +
          "; ref_label=" + gnuplot_string(ref_label) + "; lcs=" + gnuplot_string(d.lcs) +
          "; pts=" + gnuplot_string(d.pts) + "; dts=" + gnuplot_string(d.dts) +
          "; ncstab=" + std::to_string(d.cstab_blocks),
      "Work-precision of " + p.name + ": error against wall time (median of repeats), log-log, one curve "
      "per method/integrator (colour = method, point and dash = integrator; other engines, external cases, "
      "listed under \"other engines\" with asterisks and dash-dot lines; a tuned curve, matrix key tune, "
      "drawn with open points as its envelope: of its cases at every gain, those no faster one beats in error, "
      "fastest first); points from coarse to fine step size or tolerance. Top left: max |y - y_ref| at " + ref_label + "; top right: significant "
      "correct digits; bottom: largest constraint residual and largest " +
          (p.drift_name.empty() ? std::string("drift") : p.drift_name + " drift") +
          " over the run. Diverged and failed runs are left out."));
}

// <problem>_overlay: residual and drift against time, one run per method.
void add_overlay_plot(PlotSet& plots, const std::string& dir, ProblemView& p, const ProblemStyle& style,
                      const std::vector<const CaseResult*>& overlay) {
  std::string lcs;
  bool has_drift = false;
  for (const CaseResult* c : overlay) plots.series_used[c->entry->id];  // kept even if unread
  const std::string text = overlay_data(dir, overlay, style.colour, lcs, has_drift, plots.series_used);
  if (text.empty()) return;
  std::string who;
  for (const CaseResult* c : overlay) who += (who.empty() ? "" : "; ") + run_label(*c);
  p.plots.push_back(plots.add(
      p.name + "_overlay", "overlay.gp", text,
      "; problem=" + gnuplot_string(p.name) + "; has_drift=" + std::string(has_drift ? "1" : "0") +
          "; lcs=" + gnuplot_string(lcs) + "; drift_label=" +
          gnuplot_string(p.drift_name == "energy" ? "|E(t) - E(0)|" : "|drift of " + p.drift_name + "|"),
      "Constraint residual (largest over the constraints) and " +
          (p.drift_name.empty() ? std::string("conserved-quantity") : p.drift_name) + " drift against time for " +
          p.name + ", one run per method: " + who + "."));
}

// <problem>_trajectory: position coordinates against time, per method its most accurate run.
void add_trajectory_plot(PlotSet& plots, const std::string& dir, ProblemView& p, const ProblemStyle& style,
                         const std::vector<const CaseResult*>& overlay) {
  std::string lcs;
  std::vector<std::string> names;
  const auto trajectory = trajectory_runs(dir, p, overlay);
  for (const CaseResult* c : trajectory) plots.series_used[c->entry->id];  // kept even if unread
  const std::string text = trajectory_data(dir, trajectory, style.colour, lcs, names, plots.series_used);
  if (text.empty()) return;
  std::string joined, who;
  for (const auto& n : names) joined += (joined.empty() ? "" : " ") + n;
  for (const CaseResult* c : trajectory) who += (who.empty() ? "" : "; ") + run_label(*c);
  p.plots.push_back(plots.add(
      p.name + "_trajectory", "trajectory.gp", text,
      "; problem=" + gnuplot_string(p.name) + "; names=" + gnuplot_string(joined) + "; lcs=" + gnuplot_string(lcs),
      "Trajectories of " + p.name + ": position coordinates against time, per method its most accurate "
      "run against the reference: " + who + "."));
}

// Every picture of every problem (its data files written).
void plan_problem_plots(PlotSet& plots, const std::string& dir, std::vector<ProblemView>& problems) {
  for (auto& p : problems) {
    const ProblemStyle style(p);
    add_work_precision_plot(plots, p, style);
    const auto overlay = overlay_runs(dir, p);
    add_overlay_plot(plots, dir, p, style, overlay);
    add_trajectory_plot(plots, dir, p, style, overlay);
  }
}

// A section's pictures (the Stress and Scaling sections); their names in order.
std::vector<std::string> plan_section_plots(PlotSet& plots, const std::vector<StressPlot>& section_plots) {
  std::vector<std::string> names;
  for (const StressPlot& sp : section_plots)
    names.push_back(plots.add(sp.name, sp.script, sp.data, sp.vars, sp.caption));
  return names;
}

// plots/replot.sh: the exact commands, for editing a picture by hand; it
// draws PNG and SVG (FORMATS=png: the PNGs alone).
void write_replot_script(const PlotSet& plots, const std::string& scripts) {
  std::string sh = "#!/bin/sh\n# Redraws the pictures of this results folder (written by cstab report) as PNG\n"
                   "# and SVG; FORMATS=png sh replot.sh draws the PNGs alone.\nset -e\n";
  sh += "PLOTS=${CSTAB_PLOTS:-" + (scripts.empty() ? std::string("plots") : scripts) + "}\n";
  sh += "FORMATS=${FORMATS:-png svg}\n";
  for (const auto& j : plots.jobs) {
    std::string q;
    for (char c : j.vars) q += c == '"' ? std::string("\\\"") : std::string(1, c);
    sh += "gnuplot -e \"" + q + "; formats='$FORMATS'\" \"$PLOTS/" + j.script + "\"\n";
  }
  write_file_atomic(plots.plot_dir + "/replot.sh", sh);
}

// Whether job `j`'s pictures are there: the PNG, and the SVG if asked for.
bool pictures_exist(const std::string& plot_dir, const PlotJob& j, bool svg) {
  const std::string base = plot_dir + "/" + j.name;
  return fs::exists(base + ".png") && (!svg || fs::exists(base + ".svg"));
}

// Runs gnuplot for every picture whose stamp (script, style, variables, data)
// changed or whose files are missing. An SVG is drawn only with opt.svg; a
// picture redrawn without it loses its old SVG (it would no longer match).
void draw_plots(const PlotSet& plots, const std::string& scripts, const ReportOptions& opt, ReportResult& result) {
  if (scripts.empty()) {
    result.warnings.push_back("gnuplot scripts not found (set CSTAB_PLOTS to the plots/ folder): no pictures");
    return;
  }
  const std::string& plot_dir = plots.plot_dir;
  const std::string style = file_or_empty(scripts + "/style.gp");
  auto stamp_of = [&](const PlotJob& j) {
    return hash_hex(file_or_empty(scripts + "/" + j.script) + style + j.vars + j.data) + "\n";
  };
  std::vector<PlotJob> todo;
  std::error_code ec;
  for (const auto& j : plots.jobs) {
    const std::string stamp_path = plot_dir + "/data/" + j.name + ".stamp";
    if (file_or_empty(stamp_path) == stamp_of(j) && pictures_exist(plot_dir, j, opt.svg)) {
      ++result.plots_reused;
      continue;
    }
    fs::remove(stamp_path, ec);
    if (!opt.svg) fs::remove(plot_dir + "/" + j.name + ".svg", ec);
    todo.push_back(j);
  }
  std::set<std::string> drawn;
  for (const auto& f : run_gnuplot(todo, scripts, plot_dir, opt, drawn)) result.warnings.push_back(f);
  for (const auto& j : todo) {
    if (!drawn.count(j.name)) continue;
    ++result.plots_drawn;
    write_file_atomic(plot_dir + "/data/" + j.name + ".stamp", stamp_of(j));
  }
}

// ---- report.html, section by section ----

// What the page is built from.
struct Page {
  const std::string& dir;
  const std::vector<CaseResult>& results;
  const std::vector<ProblemView>& problems;
  const StressSection& stress;
  const std::vector<std::string>& stress_plots;
  const ScalingSection& scaling;
  const std::vector<std::string>& scaling_plots;
  const PlotSet& plots;
  const Provenance& prov;
  const std::vector<std::string>& warnings;
};

// Head, title line with the status counts, navigation.
void html_head(std::ostream& h, const Page& pg) {
  size_t n_ok = 0, n_div = 0, n_fail = 0, n_missing = 0, n_na = 0;
  for (const auto& c : pg.results) {
    switch (c.status) {
      case Status::kNotRun: ++n_missing; break;
      case Status::kOk: ++n_ok; break;
      case Status::kDiverged: ++n_div; break;
      case Status::kInvalid: ++n_na; break;
      default: ++n_fail;
    }
  }
  std::string date;
  for (const auto& [k, v] : pg.prov)
    if (k == "date" && date.empty()) date = v;
  h << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>cstab report: " << html_escape(pg.dir)
    << "</title>\n<style>" << kStyle << "</style>\n</head><body>\n";
  h << "<h1>cstab benchmark report</h1>\n<p class=\"meta\">Results folder <code>" << html_escape(pg.dir) << "</code>"
    << (date.empty() ? "" : ", matrix run " + html_escape(date)) << ". " << pg.results.size() << " cases: " << n_ok
    << " ok, " << n_div << " diverged, " << n_fail << " failed, " << n_na << " not applicable"
    << (n_missing ? ", " + std::to_string(n_missing) + " not run" : "")
    << ". Wall times are integration only (observation excluded), median over the repeats.</p>\n";
  h << "<nav>";
  for (const auto& p : pg.problems)
    h << "<a href=\"#problem-" << html_escape(p.name) << "\">" << html_escape(p.name) << "</a>";
  if (!pg.scaling.empty) h << "<a href=\"#scaling\">scaling</a>";
  if (!pg.stress.empty) h << "<a href=\"#stress\">stress</a>";
  h << "<a href=\"#cases\">all cases</a><a href=\"#provenance\">provenance</a></nav>\n";
}

// The fastest timed work-precision case of `p` reaching ref error <= level
// among those `take` accepts (nullptr if none).
const CaseResult* fastest_case(const ProblemView& p, double level,
                               const std::function<bool(const CaseResult&)>& take) {
  const CaseResult* best = nullptr;
  for (const CaseResult* c : p.wp)
    if (timed(*c) && c->ref_error <= level && take(*c) && (!best || c->wall_median < best->wall_median)) best = c;
  return best;
}

// The method a work-precision curve of `p` belongs to ("" if no case draws it).
std::string method_of_curve(const ProblemView& p, const std::string& curve) {
  for (const CaseResult* c : p.wp)
    if (c->entry->curve == curve) return c->entry->method;
  return {};
}

// One overview cell: the fastest curve to ref error <= level and the next method's factor.
void html_fastest_cell(std::ostream& h, const ProblemView& p, double level) {
  const auto ranked = rank_at(p.wp, kMeasures[0], level);
  if (ranked.empty()) {
    h << "<td>no stabilization method reaches it</td>";
    return;
  }
  h << "<td><span class=\"win\">" << html_escape(ranked[0]->entry->curve) << "</span> "
    << seconds_text(ranked[0]->wall_median);
  for (const CaseResult* r : ranked)
    if (r->entry->method != ranked[0]->entry->method) {
      h << "; " << html_escape(r->entry->method) << " " << sci(r->wall_median / ranked[0]->wall_median)
        << "&times; slower";
      break;
    }
  const auto limits = rank_at(p.wp, kMeasures[0], level, Role::kLimit);
  if (!limits.empty())
    h << "; " << sci(ranked[0]->wall_median / limits[0]->wall_median) << "&times; the limit "
      << html_escape(limits[0]->entry->curve);
  h << "</td>";
}

// "Matrix summary": one row per problem.
void html_overview(std::ostream& h, const Page& pg) {
  h << "<h2 id=\"overview\">Matrix summary</h2>\n<table><tr><th>problem</th><th>methods</th><th>integrators</th>"
       "<th>cases</th><th>ok</th><th>diverged</th><th>failed / not run</th><th>n/a</th>";
  for (double level : {1e-6, 1e-10})
    h << "<th>fastest stabilization method to error &le; " << sci(level) << " (vs. next method, vs. limit)</th>";
  h << "</tr>\n";
  auto joined = [](const std::set<std::string>& s) {
    std::string out;
    for (const auto& x : s) out += (out.empty() ? "" : ", ") + x;
    return out;
  };
  for (const auto& p : pg.problems) {
    std::set<std::string> methods, integrators;
    size_t ok = 0, div = 0, bad = 0, na = 0;
    for (const CaseResult* c : p.cases) {
      if (c->status == Status::kInvalid) {
        ++na;
        continue;
      }
      methods.insert(c->entry->method);
      integrators.insert(c->entry->integrator);
      if (c->status == Status::kOk)
        ++ok;
      else if (c->status == Status::kDiverged)
        ++div;
      else
        ++bad;
    }
    h << "<tr><td><a href=\"#problem-" << html_escape(p.name) << "\">" << html_escape(p.name) << "</a></td><td>"
      << html_escape(joined(methods)) << "</td><td>" << html_escape(joined(integrators)) << "</td><td class=\"num\">"
      << p.cases.size() << "</td><td class=\"num\">" << ok << "</td><td class=\"num\">" << div
      << "</td><td class=\"num\">" << bad << "</td><td class=\"num\">" << na << "</td>";
    for (double level : {1e-6, 1e-10}) html_fastest_cell(h, p, level);
    h << "</tr>\n";
  }
  h << "</table>\n";
}

// One row of a problem's "fastest method" table.
void html_fastest_row(std::ostream& h, const ProblemView& p, const Measure& m, double level) {
  const auto ranked = rank_at(p.wp, m, level);
  h << "<tr><td>"
    << (m.value == &CaseResult::drift && !p.drift_name.empty() ? "largest " + html_escape(p.drift_name) + " drift"
                                                               : m.title)
    << "</td><td class=\"num\">&le; " << sci(level) << "</td>";
  const auto limits = rank_at(p.wp, m, level, Role::kLimit);
  const std::string limit_cells =
      limits.empty() ? std::string("<td colspan=\"2\">none reaches it</td>")
                     : "<td>" + html_escape(limits[0]->entry->curve) + "</td><td class=\"num\">" +
                           seconds_text(limits[0]->wall_median) + "</td>";
  if (ranked.empty()) {
    h << "<td colspan=\"8\">no stabilization method reaches this level</td>" << limit_cells << "<td></td></tr>\n";
    return;
  }
  const CaseResult& w = *ranked[0];
  h << "<td class=\"win\">" << html_escape(w.entry->curve) << "</td><td>" << html_escape(case_setting(w))
    << "</td><td class=\"num\">" << seconds_text(w.wall_median) << "</td><td class=\"num\">" << sci(w.*(m.value))
    << "</td>";
  const CaseResult* next = nullptr;
  for (const CaseResult* r : ranked)
    if (r->entry->method != w.entry->method) {
      next = r;
      break;
    }
  if (next)
    h << "<td>" << html_escape(next->entry->curve) << "</td><td class=\"num\">" << seconds_text(next->wall_median)
      << "</td><td class=\"num\">" << sci(next->wall_median / w.wall_median) << "&times;</td>";
  else
    h << "<td colspan=\"3\">no other method reaches it</td>";
  h << "<td class=\"num\">" << ranked.size() << "</td>" << limit_cells << "<td class=\"num\">"
    << (limits.empty() ? std::string("") : sci(w.wall_median / limits[0]->wall_median) + "&times;") << "</td></tr>\n";
}

// Per problem with constraint-free baselines: at reference error 1e-6 and
// 1e-10, each stabilization method's fastest curve, ranked, its time as a
// multiple of the fastest method's and of each limit's; then the limits,
// apart.
void html_limits(std::ostream& h, const ProblemView& p) {
  std::vector<std::string> limit_methods;
  for (const CaseResult* c : p.wp)
    if (role_of(*c) == Role::kLimit &&
        std::find(limit_methods.begin(), limit_methods.end(), c->entry->method) == limit_methods.end())
      limit_methods.push_back(c->entry->method);
  if (limit_methods.empty()) return;
  h << "<h3>Stabilization methods against the limits</h3>\n<p class=\"meta\">At each level of error against the "
       "reference: each stabilization method's fastest case, ranked, with its wall time as a multiple of the fastest "
       "method's and of each limit's. A limit is a constraint-free baseline (the minimal-coordinate ODE "
       "<code>minimal</code>, the unstabilized <code>none</code>): what a method could cost at best, not a method to "
       "pick for a model without minimal coordinates. Tuned gains (<code>cstab tune</code>) move the methods "
       "closer.</p>\n<table><tr><th>error &le;</th><th>rank</th><th>fastest case</th><th>setting</th><th>wall</th>"
       "<th>&times; fastest</th>";
  for (const auto& l : limit_methods) h << "<th>&times; " << html_escape(l) << "</th>";
  h << "</tr>\n";
  // The fastest case of each method among `ranked` (fastest first).
  auto per_method = [](const std::vector<const CaseResult*>& ranked) {
    std::vector<const CaseResult*> out;
    for (const CaseResult* c : ranked)
      if (std::none_of(out.begin(), out.end(), [&](const CaseResult* o) { return o->entry->method == c->entry->method; }))
        out.push_back(c);
    return out;
  };
  for (double level : {1e-6, 1e-10}) {
    const auto methods = per_method(rank_at(p.wp, kMeasures[0], level, Role::kMethod));
    const auto limits = per_method(rank_at(p.wp, kMeasures[0], level, Role::kLimit));
    auto row = [&](const std::string& rank, const CaseResult& c) {
      h << "<tr><td class=\"num\">" << sci(level) << "</td><td>" << rank << "</td><td>"
        << html_escape(c.entry->curve) << "</td><td>" << html_escape(case_setting(c)) << "</td><td class=\"num\">"
        << seconds_text(c.wall_median) << "</td><td class=\"num\">"
        << (methods.empty() ? std::string("") : sci(c.wall_median / methods[0]->wall_median) + "&times;") << "</td>";
      for (const auto& l : limit_methods) {
        const auto it = std::find_if(limits.begin(), limits.end(),
                                     [&](const CaseResult* x) { return x->entry->method == l; });
        h << "<td class=\"num\">" << (it == limits.end() ? std::string("") : sci(c.wall_median / (*it)->wall_median) + "&times;")
          << "</td>";
      }
      h << "</tr>\n";
    };
    if (methods.empty())
      h << "<tr><td class=\"num\">" << sci(level) << "</td><td colspan=\"" << 5 + limit_methods.size()
        << "\">no stabilization method reaches it</td></tr>\n";
    for (size_t r = 0; r < methods.size(); ++r) row(std::to_string(r + 1), *methods[r]);
    for (const CaseResult* c : limits) row("<i>limit</i>", *c);
  }
  h << "</table>\n";
}

// A drawn picture, linked (plots/NAME.png beside report.html), with its
// caption; nothing if it was not drawn (no PNG, or an empty one).
void html_figure(std::ostream& h, const PlotSet& plots, const std::string& name) {
  const std::string base = plots.plot_dir + "/" + name;
  std::error_code ec;
  const auto bytes = fs::file_size(base + ".png", ec);
  if (ec || bytes == 0) return;
  const std::string file = "plots/" + url_path_escape(name);
  h << "<figure><img alt=\"" << html_escape(name) << "\" src=\"" << file << ".png\"><figcaption>"
    << html_escape(plots.captions.at(name)) << " Files: <code>plots/" << html_escape(name) << ".png</code>, "
    << (fs::exists(base + ".svg") ? "<code>plots/" + html_escape(name) + ".svg</code>"
                                  : std::string("SVG by <code>cstab report --svg</code>"))
    << ".</figcaption></figure>\n";
}

// Per problem with tuned curves (key `tune`): at reference error 1e-6 and
// 1e-10, each tuned curve's fastest case against its default-gain curve's,
// the speed-up from tuning, and the method's rank among the stabilization
// methods by default gains and tuned; a default more than 3x slower than
// the tuned one (or not reaching a level the tuned one reaches) is flagged.
void html_tuned(std::ostream& h, const ProblemView& p) {
  std::vector<std::string> tuned_curves;
  for (const std::string& curve : p.curves)
    for (const CaseResult* c : p.wp)
      if (c->entry->curve == curve && c->entry->tuned() && role_of(*c) == Role::kMethod) {
        tuned_curves.push_back(curve);
        break;
      }
  if (tuned_curves.empty()) return;
  h << "<h3>Tuned gains against the defaults</h3>\n<p class=\"meta\">Matrix key <code>tune</code>: each method's "
       "declared gain at several values around its default. At each level of error against the reference, the "
       "fastest case of the tuned curve (every gain) and of the default-gain curve, the speed-up from tuning, and "
       "the method's rank among the stabilization methods by their fastest default-gain case and by their fastest "
       "case at all. <b>flagged</b>: the default gain costs more than 3&times; the tuned one, or does not reach "
       "the level.</p>\n<table><tr><th>error &le;</th><th>tuned curve</th><th>tuned setting</th><th>wall</th>"
       "<th>default-gain setting</th><th>wall</th><th>speed-up</th><th>rank default &rarr; tuned</th>"
       "<th>defaults</th></tr>\n";
  for (double level : {1e-6, 1e-10}) {
    // The fastest case reaching `level` of each stabilization method, by default gains only and at all.
    std::map<std::string, double> by_default, at_all;
    for (const CaseResult* c : p.wp) {
      if (!timed(*c) || !(c->ref_error <= level) || role_of(*c) != Role::kMethod) continue;
      auto take = [&](std::map<std::string, double>& m) {
        auto [it, fresh] = m.emplace(c->entry->method, c->wall_median);
        if (!fresh) it->second = std::min(it->second, c->wall_median);
      };
      take(at_all);
      if (!c->entry->tuned()) take(by_default);
    }
    auto rank = [](const std::map<std::string, double>& m, const std::string& method) {
      const auto it = m.find(method);
      if (it == m.end()) return std::string("-");
      size_t r = 1;
      for (const auto& [other, wall] : m) r += wall < it->second;
      return std::to_string(r);
    };
    auto fastest_of = [&](const std::string& curve) {
      return fastest_case(p, level, [&](const CaseResult& c) { return c.entry->curve == curve; });
    };
    for (const std::string& curve : tuned_curves) {
      const CaseResult* t = fastest_of(curve);
      const CaseResult* d = fastest_of(curve.substr(0, curve.size() - kTunedSuffix.size()));
      const std::string method = method_of_curve(p, curve);
      auto cells = [](const CaseResult* c) {
        return c ? "<td>" + html_escape(case_setting(*c)) + "</td><td class=\"num\">" + seconds_text(c->wall_median) +
                       "</td>"
                 : std::string("<td>not reached</td><td></td>");
      };
      const bool flagged = t && (!d || d->wall_median > 3 * t->wall_median);
      h << "<tr><td class=\"num\">" << sci(level) << "</td><td>" << html_escape(curve) << "</td>" << cells(t)
        << cells(d) << "<td class=\"num\">" << (t && d ? sci(d->wall_median / t->wall_median) + "&times;" : "")
        << "</td><td>" << rank(by_default, method) << " &rarr; " << rank(at_all, method) << "</td><td>"
        << (flagged ? "<b>flagged</b>" : (t ? "within 3&times;" : "")) << "</td></tr>\n";
    }
  }
  h << "</table>\n";
}

// Per problem with external cases: at each reference-error level, cstab's
// fastest stabilized method (the constraint-free baselines none and minimal
// left out) against each other engine's fastest setting, as a wall-time
// ratio (scripts/peer-table.sh draws the same from work_precision.csv).
void html_other_engines(std::ostream& h, const ProblemView& p) {
  std::vector<std::string> engines;
  for (const CaseResult* c : p.wp)
    if (other_engine(*c) && std::find(engines.begin(), engines.end(), engine_of(*c)) == engines.end())
      engines.push_back(engine_of(*c));
  if (engines.empty()) return;
  auto fastest = [&](double level, const std::function<bool(const CaseResult&)>& take) {
    return fastest_case(p, level, take);
  };
  auto cell = [](const CaseResult* c) {
    return c ? "<td>" + html_escape(c->entry->curve + " " + case_setting(*c)) + "</td><td class=\"num\">" +
                   seconds_text(c->wall_median) + "</td>"
             : std::string("<td>not reached</td><td></td>");
  };
  h << "<h3>Other engines</h3>\n<p class=\"meta\">External cases (other engines run as outside programs and "
       "scored like a run): at each level of error against the reference, cstab's fastest case (none and minimal, "
       "which do not stabilize, left out) and each engine's fastest setting, with the engine's wall time as a "
       "multiple of cstab's (above 1: cstab is faster). An engine is an external curve's name up to its first "
       "'-'.</p>\n<table><tr><th>error &le;</th><th>cstab fastest</th><th>wall</th><th>engine</th>"
       "<th>engine fastest</th><th>wall</th><th>engine / cstab</th></tr>\n";
  for (double level : {1e-3, 1e-6, 1e-9}) {
    const CaseResult* ours = fastest(level, [](const CaseResult& c) { return !other_engine(c) && stabilizing(c); });
    for (const auto& engine : engines) {
      const CaseResult* theirs =
          fastest(level, [&](const CaseResult& c) { return other_engine(c) && engine_of(c) == engine; });
      h << "<tr><td class=\"num\">" << format_short(level) << "</td>" << cell(ours) << "<td>"
        << html_escape(engine) << "</td>" << cell(theirs) << "<td class=\"num\">"
        << (ours && theirs ? format_3g(theirs->wall_median / ours->wall_median) : std::string("")) << "</td></tr>\n";
    }
  }
  h << "</table>\n";
}

// Per problem: the fastest method at each accuracy level, then its pictures.
void html_problems(std::ostream& h, const Page& pg) {
  for (const auto& p : pg.problems) {
    h << "<h2 id=\"problem-" << html_escape(p.name) << "\">" << html_escape(p.name) << "</h2>\n";
    h << "<h3>Fastest method at each accuracy level</h3>\n"
         "<p class=\"meta\">Among the work-precision cases of stabilization methods that finished (status ok), the "
         "curve whose fastest case reaches the level; the runner-up is the fastest case of another method, with its "
         "time as a multiple of the winner's. The limit, apart, is the fastest constraint-free baseline "
         "(<code>minimal</code>, <code>none</code>) reaching the level, and the winner's time as a multiple of "
         "it.</p>\n";
    h << "<table><tr><th>error measure</th><th>level</th><th>fastest</th><th>setting</th><th>wall (median)</th>"
         "<th>value</th><th>next other method</th><th>its wall</th><th>factor</th><th>curves reaching</th>"
         "<th>limit</th><th>its wall</th><th>fastest / limit</th></tr>\n";
    for (const Measure& m : kMeasures) {
      if (m.value == &CaseResult::drift && p.drift_name.empty()) continue;
      for (double level : accuracy_levels()) html_fastest_row(h, p, m, level);
    }
    h << "</table>\n";
    html_limits(h, p);
    html_tuned(h, p);
    html_other_engines(h, p);
    for (const auto& name : p.plots) html_figure(h, pg.plots, name);
    if (p.plots.empty()) h << "<p>No finished runs to plot.</p>\n";
  }
}

// The Scaling section (scaling.hpp): its tables and pictures.
void html_scaling(std::ostream& h, const Page& pg) {
  if (pg.scaling.empty) return;
  h << "<h2 id=\"scaling\">Scaling</h2>\n" << pg.scaling.html;
  for (const auto& name : pg.scaling_plots) html_figure(h, pg.plots, name);
}

// The Stress section: its tables and pictures.
void html_stress(std::ostream& h, const Page& pg) {
  if (pg.stress.empty) return;
  h << "<h2 id=\"stress\">Stress</h2>\n" << pg.stress.html;
  for (const auto& name : pg.stress_plots) html_figure(h, pg.plots, name);
}

// "All cases": one row per case; the not-applicable ones folded into their own table.
void html_all_cases(std::ostream& h, const Page& pg) {
  h << "<h2 id=\"cases\">All cases</h2>\n<p class=\"meta\">One row per case (repeats folded: wall time is their "
       "median). Every repeat is a row of <code>summary.csv</code>; the tidy work-precision table is "
       "<code>work_precision.csv</code>, the rankings <code>fastest.csv</code>.</p>\n";
  h << "<div class=\"wide\"><table><tr><th>#</th><th>case_id</th><th>sweep</th><th>problem</th><th>method</th><th>formulation</th>"
       "<th>integrator</th><th>setting</th><th>t_end</th><th>status</th><th>wall (median)</th><th>repeats ok</th>"
       "<th>steps</th><th>ref error</th><th>digits</th><th>max residual</th><th>max drift</th><th>reason</th></tr>\n";
  std::map<std::string, std::pair<size_t, std::string>> not_applicable;  // "problem method integrator" -> count, reason
  for (const CaseResult& c : pg.results) {
    if (c.status == Status::kInvalid) {
      auto& slot = not_applicable[c.entry->problem + " / " + c.entry->method + " / " + c.entry->integrator];
      ++slot.first;
      slot.second = c.reason;
      continue;
    }
    const char* cls = c.status == Status::kOk ? "" : c.status == Status::kDiverged ? " class=\"div\"" : " class=\"bad\"";
    h << "<tr" << cls << "><td class=\"num\">" << c.entry->index << "</td><td><code>" << c.entry->id
      << "</code></td><td>" << html_escape(c.entry->sweep) << "</td><td>" << html_escape(c.entry->problem)
      << "</td><td>" << html_escape(c.entry->method) << "</td><td>" << html_escape(c.formulation) << "</td><td>"
      << html_escape(c.entry->integrator) << "</td><td>" << html_escape(case_setting(c)) << "</td><td class=\"num\">"
      << format_short(c.entry->t_end) << "</td><td>" << html_escape(status_name(c.status))
      << "</td><td class=\"num\">" << seconds_text(c.wall_median) << "</td><td class=\"num\">" << c.ok_repeats << "/"
      << c.entry->repeats << "</td><td class=\"num\">" << count_cell(c.steps) << "</td><td class=\"num\">"
      << sci(c.ref_error) << "</td><td class=\"num\">" << (std::isnan(c.ref_scd) ? "" : sci(c.ref_scd))
      << "</td><td class=\"num\">" << sci(c.max_residual) << "</td><td class=\"num\">" << sci(c.drift)
      << "</td><td class=\"reason\">" << html_escape(c.reason) << "</td></tr>\n";
  }
  h << "</table></div>\n";
  if (not_applicable.empty()) return;
  h << "<h3>Not applicable</h3>\n<p class=\"meta\">Combinations the harness rejected before running "
       "(status <code>invalid</code> in summary.csv).</p>\n<table><tr><th>problem / method / integrator</th>"
       "<th>cases</th><th>reason</th></tr>\n";
  for (const auto& [key, v] : not_applicable)
    h << "<tr><td>" << html_escape(key) << "</td><td class=\"num\">" << v.first << "</td><td>"
      << html_escape(v.second) << "</td></tr>\n";
  h << "</table>\n";
}

// Provenance, the matrix, warnings and the image-check script.
void html_tail(std::ostream& h, const Page& pg) {
  h << "<h2 id=\"provenance\">Provenance</h2>\n<table>";
  if (pg.prov.empty()) h << "<tr><td>no provenance.txt in this folder</td></tr>";
  for (const auto& [k, v] : pg.prov) h << "<tr><th>" << html_escape(k) << "</th><td>" << html_escape(v) << "</td></tr>\n";
  h << "</table>\n<details><summary>The matrix (matrix.toml)</summary><pre>"
    << html_escape(file_or_empty(pg.dir + "/matrix.toml")) << "</pre></details>\n";
  for (const auto& w : pg.warnings) h << "<p class=\"meta\">warning: " << html_escape(w) << "</p>\n";
  // Marks the page once every image has been decoded; scripts/check-report.sh reads these attributes.
  h << R"(<script>
window.addEventListener('load', function () {
  var imgs = document.images, ok = 0;
  for (var i = 0; i < imgs.length; i++) if (imgs[i].complete && imgs[i].naturalWidth > 0) ok++;
  document.documentElement.setAttribute('data-images-total', String(imgs.length));
  document.documentElement.setAttribute('data-images-loaded', String(ok));
});
</script>
</body></html>
)";
}

// The whole page.
std::string report_html(const Page& pg) {
  std::ostringstream h;
  html_head(h, pg);
  html_overview(h, pg);
  html_problems(h, pg);
  html_scaling(h, pg);
  html_stress(h, pg);
  html_all_cases(h, pg);
  html_tail(h, pg);
  return h.str();
}

}  // namespace

ReportResult build_report(const std::string& dir, const ReportOptions& opt, std::ostream& log) {
  ReportResult result;
  // Parse the folder once.
  const ResultsFolder folder = load_report_input(dir);
  // Group the cases by problem.
  std::vector<ProblemView> problems = group_by_problem(folder.cases);
  // The tables.
  write_work_precision_csv(dir, problems);
  write_fastest_csv(dir, problems);
  // The pictures' data, per problem and for the Stress section.
  PlotSet plots;
  plots.plot_dir = dir + "/plots";
  std::error_code ec;
  fs::create_directories(plots.plot_dir + "/data", ec);
  plan_problem_plots(plots, dir, problems);
  const StressSection stress = build_stress_section(folder);
  const std::vector<std::string> stress_plots = plan_section_plots(plots, stress.plots);
  const ScalingSection scaling = build_scaling_section(folder);
  const std::vector<std::string> scaling_plots = plan_section_plots(plots, scaling.plots);
  // replot.sh, then gnuplot for what changed.
  const std::string scripts = opt.plot_scripts.empty() ? find_plot_scripts() : opt.plot_scripts;
  write_replot_script(plots, scripts);
  if (opt.plots) draw_plots(plots, scripts, opt, result);
  result.series_used = plots.series_used;
  for (const auto& [id, columns] : stress.series_used) result.series_used[id].insert(columns.begin(), columns.end());
  // report.html.
  const Provenance prov = parse_provenance(file_or_empty(dir + "/provenance.txt"));
  const Page page{dir,     folder.cases,  problems, stress, stress_plots,
                  scaling, scaling_plots, plots,    prov,   result.warnings};
  result.html = dir + "/report.html";
  write_file_atomic(result.html, report_html(page));
  for (const auto& w : result.warnings) log << "report: warning: " << w << "\n";
  return result;
}

}  // namespace cstab

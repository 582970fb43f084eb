#include "report/report.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "io/csv.hpp"
#include "core/format.hpp"
#include "matrix/matrix.hpp"
#include "matrix/provenance.hpp"
#include "report/stress_report.hpp"

#ifndef CSTAB_SOURCE_ROOT
#define CSTAB_SOURCE_ROOT ""
#endif

namespace cstab {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double to_number(const std::string& s) {
  if (s.empty()) return kNaN;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  return end == s.c_str() ? kNaN : v;
}

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string num(double v) { return std::isnan(v) ? std::string() : format_exact(v); }

// Short human form: 3 significant digits.
std::string sci(double v) {
  if (std::isnan(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

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

std::string html(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string base64(const std::string& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    const unsigned v = (unsigned char)data[i] << 16 | (unsigned char)data[i + 1] << 8 | (unsigned char)data[i + 2];
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += table[v & 63];
  }
  if (i + 1 == data.size()) {
    const unsigned v = (unsigned char)data[i] << 16;
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == data.size()) {
    const unsigned v = (unsigned char)data[i] << 16 | (unsigned char)data[i + 1] << 8;
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

// Gnuplot single-quoted string literal.
std::string gp_string(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string csv_line(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += csv_field(cells[i]);
  }
  return line + "\n";
}

// A value for a log-scale plot column: "?" (missing) unless finite and > 0.
std::string log_cell(double v) { return std::isfinite(v) && v > 0 ? format_exact(v) : "?"; }

// ---------------------------------------------------------------------------

struct CaseResult {
  const CaseEntry* entry = nullptr;
  bool complete = false;
  std::string status = "not run", reason, formulation;
  int ok_repeats = 0;
  double wall_median = kNaN, wall_min = kNaN, wall_max = kNaN;
  std::string steps, rhs_evals;
  double step = kNaN, rtol = kNaN, atol = kNaN;
  double ref_time = kNaN, ref_error = kNaN, ref_scd = kNaN, max_residual = kNaN, drift = kNaN;
  std::string drift_name;  // "energy", "first integrals (a, b)", ""
  bool ok() const { return complete && status == "ok" && std::isfinite(wall_median); }
  double size() const { return std::isnan(step) ? rtol : step; }  // coarse -> fine ordering
};

std::vector<CaseResult> load_results(const std::vector<CaseEntry>& entries, const CsvTable& summary) {
  std::map<std::string, std::vector<size_t>> rows_of;
  const int id_col = summary.column("case_id");
  for (size_t r = 0; r < summary.rows.size(); ++r)
    if (id_col >= 0 && size_t(id_col) < summary.rows[r].size()) rows_of[summary.rows[r][id_col]].push_back(r);
  std::vector<std::string> integral_cols;
  for (const auto& h : summary.header)
    if (h.rfind("max_", 0) == 0 && h.size() > 10 && h.compare(h.size() - 6, 6, "_drift") == 0 &&
        h != "max_energy_drift")
      integral_cols.push_back(h);

  std::vector<CaseResult> out;
  for (const auto& e : entries) {
    CaseResult c;
    c.entry = &e;
    auto it = rows_of.find(e.id);
    if (it != rows_of.end() && !it->second.empty()) {
      c.complete = true;
      const size_t r0 = it->second.front();
      auto get = [&](const char* col) -> const std::string& { return summary.get(r0, col); };
      c.status = get("status");
      c.reason = get("reason");
      c.formulation = get("formulation");
      c.steps = get("steps");
      c.rhs_evals = get("rhs_evals");
      c.step = to_number(get("step"));
      c.rtol = to_number(get("rtol"));
      c.atol = to_number(get("atol"));
      c.ref_time = to_number(get("ref_time"));
      c.ref_error = to_number(get("ref_error"));
      c.ref_scd = to_number(get("ref_scd"));
      c.max_residual = to_number(get("max_residual"));
      if (get("energy_law") == "yes") {
        c.drift = to_number(get("max_energy_drift"));
        c.drift_name = "energy";
      } else {
        std::string names;
        for (const auto& col : integral_cols) {
          const double v = to_number(summary.get(r0, col));
          if (std::isnan(v)) continue;
          c.drift = std::isnan(c.drift) ? v : std::max(c.drift, v);
          names += (names.empty() ? "" : ", ") + col.substr(4, col.size() - 10);
        }
        if (!names.empty()) c.drift_name = "first integrals (" + names + ")";
      }
      std::vector<double> walls;
      for (size_t r : it->second)
        if (summary.get(r, "status") == "ok") walls.push_back(to_number(summary.get(r, "wall_seconds")));
      c.ok_repeats = int(walls.size());
      if (!walls.empty()) {
        c.wall_median = median(walls);
        c.wall_min = *std::min_element(walls.begin(), walls.end());
        c.wall_max = *std::max_element(walls.begin(), walls.end());
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}

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

// Curves reaching `level` in `measure`, each with its fastest such case, fastest first.
std::vector<const CaseResult*> rank_at(const std::vector<const CaseResult*>& cases, const Measure& m, double level) {
  std::map<std::string, const CaseResult*> best;
  for (const CaseResult* c : cases) {
    const double v = c->*(m.value);
    if (!c->ok() || !(v <= level)) continue;
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
  return c->complete && fs::exists(dir + "/cases/" + c->entry->id + "/series.csv");
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
      if (!pick && c->entry->method == m && c->entry->overlay && c->ok() && has_series(dir, c)) pick = c;
    if (!pick)
      for (const CaseResult* c : p.cases) {
        if (c->entry->method != m || !c->ok() || !has_series(dir, c)) continue;
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
      if (c->entry->method == m && c->ok() && std::isfinite(c->ref_error) && has_series(dir, c) &&
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
  if (c.status != "ok") s += " (" + c.status + ")";
  return s;
}

std::string quoted_header(const std::string& label, const std::vector<std::string>& rest) {
  std::string h = "\"";
  for (char ch : label) h += ch == '"' ? '\'' : ch;
  h += "\"";
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
  return size_t(col) < row.size() ? to_number(row[col]) : kNaN;
}

// A case's series.csv; empty if it is missing or unreadable.
CsvTable read_series(const std::string& dir, const CaseResult& c) {
  try {
    return read_csv(dir + "/cases/" + c.entry->id + "/series.csv");
  } catch (const std::exception&) {
    return {};
  }
}

// Overlay data: per run, t, max |residual|, |drift|. Colours in `lcs`.
std::string overlay_data(const std::string& dir, const std::vector<const CaseResult*>& runs,
                         const std::map<std::string, int>& colour, std::string& lcs, bool& has_drift) {
  std::string out;
  has_drift = false;
  for (const CaseResult* c : runs) {
    const CsvTable s = read_series(dir, *c);
    if (s.rows.empty()) continue;  // missing or unreadable: the run is left out
    const SeriesColumns cols = classify(s);
    has_drift = has_drift || !cols.drifts.empty();
    if (!out.empty()) out += "\n\n";
    out += quoted_header(run_label(*c), {"max_abs_residual", "abs_drift"});
    lcs += " " + std::to_string(colour.at(c->entry->method));
    for (const auto& row : s.rows) {
      double res = cols.residuals.empty() ? kNaN : 0.0, drift = cols.drifts.empty() ? kNaN : 0.0;
      for (int col : cols.residuals) res = std::max(res, std::abs(cell(row, col)));
      for (int col : cols.drifts) drift = std::max(drift, std::abs(cell(row, col)));
      out += row[0] + " " + log_cell(res) + " " + log_cell(drift) + "\n";
    }
  }
  return out;
}

// Trajectory data: per run, t and the position coordinates (names not
// ending in "dot"; at most 9). Colours in `lcs`, coordinate names in `names`.
std::string trajectory_data(const std::string& dir, const std::vector<const CaseResult*>& runs,
                            const std::map<std::string, int>& colour, std::string& lcs,
                            std::vector<std::string>& names) {
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
    std::vector<std::string> these;
    for (int col : shown) these.push_back(s.header[col]);
    if (out.empty()) names = these;
    if (these != names) continue;  // every block has the same columns
    if (!out.empty()) out += "\n\n";
    out += quoted_header(run_label(*c), names);
    lcs += " " + std::to_string(colour.at(c->entry->method));
    for (const auto& row : s.rows) {
      out += row[0];
      for (int col : shown) {
        const double v = cell(row, col);
        out += ' ';
        out += std::isfinite(v) ? format_exact(v) : std::string("?");
      }
      out += "\n";
    }
  }
  return out;
}

// Runs the jobs, `jobs` gnuplot processes at a time; returns failures.
std::vector<std::string> run_gnuplot(const std::vector<PlotJob>& todo, const std::string& scripts,
                                     const std::string& plot_dir, int jobs, std::set<std::string>& drawn) {
  std::vector<std::string> failures;
  std::map<pid_t, const PlotJob*> running;
  size_t next = 0;
  while (next < todo.size() || !running.empty()) {
    while (running.size() < size_t(std::max(1, jobs)) && next < todo.size()) {
      const PlotJob& job = todo[next++];
      const std::string script = scripts + "/" + job.script;
      const std::string log_path = plot_dir + "/data/" + job.name + ".log";
      std::fflush(nullptr);
      const pid_t pid = ::fork();
      if (pid == 0) {
        std::FILE* log = std::fopen(log_path.c_str(), "w");
        if (log) {
          ::dup2(::fileno(log), 1);
          ::dup2(::fileno(log), 2);
        }
        ::execlp("gnuplot", "gnuplot", "-e", job.vars.c_str(), script.c_str(), (char*)nullptr);
        ::_exit(127);
      }
      if (pid < 0) {
        failures.push_back(job.name + ": cannot start gnuplot");
        continue;
      }
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
    if (ok) drawn.insert(job.name);
    if (!ok) {
      std::string why = WIFEXITED(status) && WEXITSTATUS(status) == 127 ? "gnuplot not found" : "gnuplot failed";
      failures.push_back(job.name + ": " + why + " (see " + plot_dir + "/data/" + job.name + ".log)");
    }
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

ReportResult build_report(const std::string& dir, const ReportOptions& opt, std::ostream& log) {
  ReportResult result;
  const std::vector<CaseEntry> entries = read_results_manifest(dir);
  CsvTable summary;
  try {
    summary = read_csv(dir + "/summary.csv");
  } catch (const std::exception&) {
    write_matrix_summary(dir, entries);
    summary = read_csv(dir + "/summary.csv");
  }
  const std::vector<CaseResult> results = load_results(entries, summary);

  // ---- per problem ----
  std::vector<ProblemView> problems;
  for (const CaseResult& c : results) {
    auto it = std::find_if(problems.begin(), problems.end(), [&](const ProblemView& p) { return p.name == c.entry->problem; });
    if (it == problems.end()) {
      problems.push_back({});
      problems.back().name = c.entry->problem;
      it = problems.end() - 1;
    }
    it->cases.push_back(&c);
    if (std::find(it->methods.begin(), it->methods.end(), c.entry->method) == it->methods.end())
      it->methods.push_back(c.entry->method);
    if (std::find(it->integrators.begin(), it->integrators.end(), c.entry->integrator) == it->integrators.end())
      it->integrators.push_back(c.entry->integrator);
    if (c.entry->work_precision) {
      it->wp.push_back(&c);
      if (std::find(it->curves.begin(), it->curves.end(), c.entry->curve) == it->curves.end())
        it->curves.push_back(c.entry->curve);
    }
    if (it->drift_name.empty()) it->drift_name = c.drift_name;
    if (std::isnan(it->ref_time) && c.ok()) it->ref_time = c.ref_time;
  }

  // ---- work_precision.csv and fastest.csv ----
  {
    std::string csv =
        "problem,curve,method,formulation,integrator,params,setting,step,rtol,atol,t_end,case_id,sweep,repeats,"
        "status,wall_median_s,wall_min_s,wall_max_s,steps,rhs_evals,ref_time,ref_error,ref_scd,max_residual,"
        "drift_quantity,max_drift\n";
    for (const auto& p : problems)
      for (const CaseResult* c : p.wp) {
        const CaseEntry& e = *c->entry;
        const std::vector<std::string> cells = {
            e.problem, e.curve, e.method, c->formulation, e.integrator, e.params, e.setting, num(c->step),
            num(c->rtol), num(c->atol), format_short(e.t_end), e.id, e.sweep, std::to_string(e.repeats), c->status,
            num(c->wall_median), num(c->wall_min), num(c->wall_max), c->steps, c->rhs_evals, num(c->ref_time),
            num(c->ref_error), num(c->ref_scd), num(c->max_residual), c->drift_name, num(c->drift)};
        csv += csv_line(cells);
      }
    write_file_atomic(dir + "/work_precision.csv", csv);

    std::string fast =
        "problem,measure,threshold,rank,curve,method,integrator,case_id,setting,wall_median_s,value,"
        "ratio_to_fastest\n";
    for (const auto& p : problems)
      for (const Measure& m : kMeasures)
        for (double level : accuracy_levels()) {
          const auto ranked = rank_at(p.wp, m, level);
          for (size_t r = 0; r < ranked.size(); ++r) {
            const CaseResult& c = *ranked[r];
            const std::vector<std::string> cells = {
                p.name, m.key, format_short(level), std::to_string(r + 1), c.entry->curve, c.entry->method,
                c.entry->integrator, c.entry->id, case_setting(c), num(c.wall_median), num(c.*(m.value)),
                num(c.wall_median / ranked[0]->wall_median)};
            fast += csv_line(cells);
          }
        }
    write_file_atomic(dir + "/fastest.csv", fast);
  }

  // ---- plot data and gnuplot ----
  const std::string plot_dir = dir + "/plots";
  std::error_code ec;
  fs::create_directories(plot_dir + "/data", ec);
  std::vector<PlotJob> jobs;
  std::map<std::string, std::string> captions;
  for (auto& p : problems) {
    // Colour = method, point type and dash = integrator, the same in every picture of the problem.
    std::map<std::string, int> colour;
    for (size_t i = 0; i < p.methods.size(); ++i) colour[p.methods[i]] = int(i % 12) + 1;
    auto integrator_style = [&](const std::string& name) {
      static const int points[] = {7, 5, 9, 11, 13, 15, 4, 6, 8, 10};
      const size_t j = size_t(std::find(p.integrators.begin(), p.integrators.end(), name) - p.integrators.begin());
      return std::make_pair(points[j % 10], int(j % 5) + 1);
    };
    const std::string drift_label =
        p.drift_name == "energy" ? "max |E(t) - E(0)|"
                                 : (p.drift_name.empty() ? "max drift (no energy law or first integral)"
                                                         : "max drift of " + p.drift_name);
    const std::string ref_label = std::isnan(p.ref_time) ? "the reference time" : "t = " + format_short(p.ref_time);
    // Work-precision data: one block per curve, coarse to fine.
    std::string wp, lcs, pts, dts;
    size_t blocks = 0;
    bool has_ref = false, has_drift_values = false;
    for (const auto& curve : p.curves) {
      std::vector<const CaseResult*> pts_of;
      for (const CaseResult* c : p.wp)
        if (c->entry->curve == curve && c->ok()) pts_of.push_back(c);
      if (pts_of.empty()) continue;
      std::stable_sort(pts_of.begin(), pts_of.end(), [](const CaseResult* a, const CaseResult* b) {
        return a->entry->t_end != b->entry->t_end ? a->entry->t_end < b->entry->t_end : a->size() > b->size();
      });
      if (blocks++) wp += "\n\n";
      wp += quoted_header(curve, {"wall_median_s", "ref_error", "ref_scd", "max_residual", "max_drift", "setting"});
      const auto [point, dash] = integrator_style(pts_of[0]->entry->integrator);
      lcs += " " + std::to_string(colour[pts_of[0]->entry->method]);
      pts += " " + std::to_string(point);
      dts += " " + std::to_string(dash);
      for (const CaseResult* c : pts_of) {
        has_ref = has_ref || (std::isfinite(c->ref_error) && c->ref_error > 0);
        has_drift_values = has_drift_values || (std::isfinite(c->drift) && c->drift > 0);
      }
      for (const CaseResult* c : pts_of)
        wp += format_exact(c->wall_median) + " " + log_cell(c->ref_error) + " " +
              (std::isfinite(c->ref_scd) ? format_exact(c->ref_scd) : "?") + " " + log_cell(c->max_residual) + " " +
              log_cell(c->drift) + " " + format_exact(c->size()) + "\n";
    }
    const std::string base = plot_dir + "/data/";
    auto add_job = [&](const std::string& kind, const std::string& script, const std::string& data,
                       const std::string& extra_vars, const std::string& caption) {
      const std::string name = p.name + "_" + kind;
      const std::string data_path = base + name + ".dat";
      write_file_atomic(data_path, data);
      const std::string vars = "data=" + gp_string(data_path) + "; out=" + gp_string(plot_dir + "/" + name) +
                               "; problem=" + gp_string(p.name) + extra_vars;
      jobs.push_back({name, script, vars, data, caption});
      p.plots.push_back(name);
      captions[name] = caption;
    };
    if (blocks)
      add_job("work_precision", "work_precision.gp", wp,
              "; has_ref=" + std::string(has_ref ? "1" : "0") + "; has_drift=" + (has_drift_values ? "1" : "0") +
                  "; drift_label=" + gp_string(drift_label) + "; ref_label=" + gp_string(ref_label) + "; lcs=" +
                  gp_string(lcs) + "; pts=" + gp_string(pts) + "; dts=" + gp_string(dts),
              "Work-precision of " + p.name + ": error against wall time (median of repeats), log-log, one curve "
              "per method/integrator (colour = method, point and dash = integrator); points from coarse to fine "
              "step size or tolerance. Top left: max |y - y_ref| at " + ref_label + "; top right: significant "
              "correct digits; bottom: largest constraint residual and largest " +
                  (p.drift_name.empty() ? std::string("drift") : p.drift_name + " drift") +
                  " over the run. Diverged and failed runs are left out.");
    const auto overlay = overlay_runs(dir, p);
    std::string overlay_lcs, trajectory_lcs;
    bool has_drift = false;
    const std::string overlay_text = overlay_data(dir, overlay, colour, overlay_lcs, has_drift);
    if (!overlay_text.empty()) {
      std::string who;
      for (const CaseResult* c : overlay) who += (who.empty() ? "" : "; ") + run_label(*c);
      add_job("overlay", "overlay.gp", overlay_text,
              "; has_drift=" + std::string(has_drift ? "1" : "0") + "; lcs=" + gp_string(overlay_lcs) +
                  "; drift_label=" +
                  gp_string(p.drift_name == "energy" ? "|E(t) - E(0)|" : "|drift of " + p.drift_name + "|"),
              "Constraint residual (largest over the constraints) and " +
                  (p.drift_name.empty() ? std::string("conserved-quantity") : p.drift_name) +
                  " drift against time for " + p.name + ", one run per method: " + who + ".");
    }
    std::vector<std::string> names;
    const auto trajectory = trajectory_runs(dir, p, overlay);
    const std::string trajectory_text = trajectory_data(dir, trajectory, colour, trajectory_lcs, names);
    if (!trajectory_text.empty()) {
      std::string joined, who;
      for (const auto& n : names) joined += (joined.empty() ? "" : " ") + n;
      for (const CaseResult* c : trajectory) who += (who.empty() ? "" : "; ") + run_label(*c);
      add_job("trajectory", "trajectory.gp", trajectory_text,
              "; names=" + gp_string(joined) + "; lcs=" + gp_string(trajectory_lcs),
              "Trajectories of " + p.name + ": position coordinates against time, per method its most accurate "
              "run against the reference: " + who + ".");
    }
  }

  // The Stress section (stress_report.hpp): its tables and pictures.
  const StressSection stress = build_stress_section(dir, entries, summary);
  std::vector<std::string> stress_plots;
  for (const StressPlot& sp : stress.plots) {
    const std::string data_path = plot_dir + "/data/" + sp.name + ".dat";
    write_file_atomic(data_path, sp.data);
    jobs.push_back({sp.name, sp.script, "data=" + gp_string(data_path) + "; out=" + gp_string(plot_dir + "/" + sp.name) + sp.vars,
                    sp.data, sp.caption});
    captions[sp.name] = sp.caption;
    stress_plots.push_back(sp.name);
  }

  // replot.sh: the exact commands, for editing a picture by hand.
  const std::string scripts = opt.plot_scripts.empty() ? find_plot_scripts() : opt.plot_scripts;
  {
    std::string sh = "#!/bin/sh\n# Redraws the pictures of this results folder (written by cstab report).\nset -e\n";
    sh += "PLOTS=${CSTAB_PLOTS:-" + (scripts.empty() ? std::string("plots") : scripts) + "}\n";
    for (const auto& j : jobs) {
      std::string q;
      for (char c : j.vars) q += c == '"' ? std::string("\\\"") : std::string(1, c);
      sh += "gnuplot -e \"" + q + "\" \"$PLOTS/" + j.script + "\"\n";
    }
    write_file_atomic(plot_dir + "/replot.sh", sh);
  }
  if (opt.plots) {
    if (scripts.empty()) {
      result.warnings.push_back("gnuplot scripts not found (set CSTAB_PLOTS to the plots/ folder): no pictures");
    } else {
      const std::string style = file_or_empty(scripts + "/style.gp");
      std::vector<PlotJob> todo;
      for (const auto& j : jobs) {
        const std::string stamp =
            hash_hex(file_or_empty(scripts + "/" + j.script) + style + j.vars + j.data) + "\n";
        const std::string stamp_path = plot_dir + "/data/" + j.name + ".stamp";
        if (file_or_empty(stamp_path) == stamp && fs::exists(plot_dir + "/" + j.name + ".png") &&
            fs::exists(plot_dir + "/" + j.name + ".svg")) {
          ++result.plots_reused;
          continue;
        }
        fs::remove(stamp_path, ec);
        todo.push_back(j);
      }
      std::set<std::string> drawn;
      for (const auto& f : run_gnuplot(todo, scripts, plot_dir, opt.jobs, drawn)) result.warnings.push_back(f);
      for (const auto& j : todo) {
        if (!drawn.count(j.name)) continue;
        ++result.plots_drawn;
        write_file_atomic(plot_dir + "/data/" + j.name + ".stamp",
                          hash_hex(file_or_empty(scripts + "/" + j.script) + style + j.vars + j.data) + "\n");
      }
    }
  }

  // ---- report.html ----
  size_t n_ok = 0, n_div = 0, n_fail = 0, n_missing = 0, n_na = 0;
  for (const auto& c : results) {
    if (!c.complete)
      ++n_missing;
    else if (c.status == "ok")
      ++n_ok;
    else if (c.status == "diverged")
      ++n_div;
    else if (c.status == "invalid")
      ++n_na;
    else
      ++n_fail;
  }
  const Provenance prov = parse_provenance(file_or_empty(dir + "/provenance.txt"));
  std::string date;
  for (const auto& [k, v] : prov)
    if (k == "date" && date.empty()) date = v;

  std::ostringstream h;
  h << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>cstab report: " << html(dir)
    << "</title>\n<style>" << kStyle << "</style>\n</head><body>\n";
  h << "<h1>cstab benchmark report</h1>\n<p class=\"meta\">Results folder <code>" << html(dir) << "</code>"
    << (date.empty() ? "" : ", matrix run " + html(date)) << ". " << results.size() << " cases: " << n_ok << " ok, "
    << n_div << " diverged, " << n_fail << " failed, " << n_na << " not applicable"
    << (n_missing ? ", " + std::to_string(n_missing) + " not run" : "")
    << ". Wall times are integration only (observation excluded), median over the repeats.</p>\n";
  h << "<nav>";
  for (const auto& p : problems) h << "<a href=\"#problem-" << html(p.name) << "\">" << html(p.name) << "</a>";
  if (!stress.empty) h << "<a href=\"#stress\">stress</a>";
  h << "<a href=\"#cases\">all cases</a><a href=\"#provenance\">provenance</a></nav>\n";

  // Overview.
  h << "<h2 id=\"overview\">Matrix summary</h2>\n<table><tr><th>problem</th><th>methods</th><th>integrators</th>"
       "<th>cases</th><th>ok</th><th>diverged</th><th>failed / not run</th><th>n/a</th>";
  for (double level : {1e-6, 1e-10})
    h << "<th>fastest to error &le; " << sci(level) << " (vs. next method)</th>";
  h << "</tr>\n";
  for (const auto& p : problems) {
    std::set<std::string> methods, integrators;
    size_t ok = 0, div = 0, bad = 0, na = 0;
    for (const CaseResult* c : p.cases) {
      if (c->complete && c->status == "invalid") {
        ++na;
        continue;
      }
      methods.insert(c->entry->method);
      integrators.insert(c->entry->integrator);
      if (!c->complete || (c->status != "ok" && c->status != "diverged"))
        ++bad;
      else if (c->status == "ok")
        ++ok;
      else
        ++div;
    }
    auto joined = [](const std::set<std::string>& s) {
      std::string out;
      for (const auto& x : s) out += (out.empty() ? "" : ", ") + x;
      return out;
    };
    h << "<tr><td><a href=\"#problem-" << html(p.name) << "\">" << html(p.name) << "</a></td><td>"
      << html(joined(methods)) << "</td><td>" << html(joined(integrators)) << "</td><td class=\"num\">"
      << p.cases.size() << "</td><td class=\"num\">" << ok << "</td><td class=\"num\">" << div
      << "</td><td class=\"num\">" << bad << "</td><td class=\"num\">" << na << "</td>";
    for (double level : {1e-6, 1e-10}) {
      const auto ranked = rank_at(p.wp, kMeasures[0], level);
      if (ranked.empty()) {
        h << "<td>none reaches it</td>";
        continue;
      }
      h << "<td><span class=\"win\">" << html(ranked[0]->entry->curve) << "</span> "
        << seconds_text(ranked[0]->wall_median);
      for (const CaseResult* r : ranked)
        if (r->entry->method != ranked[0]->entry->method) {
          h << "; " << html(r->entry->method) << " " << sci(r->wall_median / ranked[0]->wall_median) << "&times; slower";
          break;
        }
      h << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";

  // Per problem.
  for (const auto& p : problems) {
    h << "<h2 id=\"problem-" << html(p.name) << "\">" << html(p.name) << "</h2>\n";
    h << "<h3>Fastest method at each accuracy level</h3>\n"
         "<p class=\"meta\">Among the work-precision cases that finished (status ok), the curve whose fastest case "
         "reaches the level; the runner-up is the fastest case of another method, with its time as a multiple of "
         "the winner's.</p>\n";
    h << "<table><tr><th>error measure</th><th>level</th><th>fastest</th><th>setting</th><th>wall (median)</th>"
         "<th>value</th><th>next other method</th><th>its wall</th><th>factor</th><th>curves reaching</th></tr>\n";
    for (const Measure& m : kMeasures) {
      if (m.value == &CaseResult::drift && p.drift_name.empty()) continue;
      for (double level : accuracy_levels()) {
        const auto ranked = rank_at(p.wp, m, level);
        h << "<tr><td>" << (m.value == &CaseResult::drift && !p.drift_name.empty() ? "largest " + html(p.drift_name) + " drift" : m.title)
          << "</td><td class=\"num\">&le; " << sci(level) << "</td>";
        if (ranked.empty()) {
          h << "<td colspan=\"8\">no case reaches this level</td></tr>\n";
          continue;
        }
        const CaseResult& w = *ranked[0];
        h << "<td class=\"win\">" << html(w.entry->curve) << "</td><td>" << html(case_setting(w))
          << "</td><td class=\"num\">" << seconds_text(w.wall_median) << "</td><td class=\"num\">" << sci(w.*(m.value))
          << "</td>";
        const CaseResult* next = nullptr;
        for (const CaseResult* r : ranked)
          if (r->entry->method != w.entry->method) {
            next = r;
            break;
          }
        if (next)
          h << "<td>" << html(next->entry->curve) << "</td><td class=\"num\">" << seconds_text(next->wall_median)
            << "</td><td class=\"num\">" << sci(next->wall_median / w.wall_median) << "&times;</td>";
        else
          h << "<td colspan=\"3\">no other method reaches it</td>";
        h << "<td class=\"num\">" << ranked.size() << " of " << p.curves.size() << "</td></tr>\n";
      }
    }
    h << "</table>\n";
    for (const auto& name : p.plots) {
      const std::string png = file_or_empty(plot_dir + "/" + name + ".png");
      if (png.empty()) continue;
      h << "<figure><img alt=\"" << html(name) << "\" src=\"data:image/png;base64," << base64(png)
        << "\"><figcaption>" << html(captions[name]) << " Files: <code>plots/" << html(name)
        << ".png</code>, <code>plots/" << html(name) << ".svg</code>.</figcaption></figure>\n";
    }
    if (p.plots.empty()) h << "<p>No finished runs to plot.</p>\n";
  }

  // Stress tests.
  if (!stress.empty) {
    h << "<h2 id=\"stress\">Stress</h2>\n" << stress.html;
    for (const auto& name : stress_plots) {
      const std::string png = file_or_empty(plot_dir + "/" + name + ".png");
      if (png.empty()) continue;
      h << "<figure><img alt=\"" << html(name) << "\" src=\"data:image/png;base64," << base64(png)
        << "\"><figcaption>" << html(captions[name]) << " Files: <code>plots/" << html(name)
        << ".png</code>, <code>plots/" << html(name) << ".svg</code>.</figcaption></figure>\n";
    }
  }

  // All cases.
  h << "<h2 id=\"cases\">All cases</h2>\n<p class=\"meta\">One row per case (repeats folded: wall time is their "
       "median). Every repeat is a row of <code>summary.csv</code>; the tidy work-precision table is "
       "<code>work_precision.csv</code>, the rankings <code>fastest.csv</code>.</p>\n";
  h << "<div class=\"wide\"><table><tr><th>#</th><th>case_id</th><th>sweep</th><th>problem</th><th>method</th><th>formulation</th>"
       "<th>integrator</th><th>setting</th><th>t_end</th><th>status</th><th>wall (median)</th><th>repeats ok</th>"
       "<th>steps</th><th>ref error</th><th>digits</th><th>max residual</th><th>max drift</th><th>reason</th></tr>\n";
  std::map<std::string, std::pair<size_t, std::string>> not_applicable;  // "problem method integrator" -> count, reason
  for (const CaseResult& c : results) {
    if (c.complete && c.status == "invalid") {
      auto& slot = not_applicable[c.entry->problem + " / " + c.entry->method + " / " + c.entry->integrator];
      ++slot.first;
      slot.second = c.reason;
      continue;
    }
    const char* cls = !c.complete || (c.status != "ok" && c.status != "diverged") ? " class=\"bad\""
                      : c.status == "diverged"                                     ? " class=\"div\""
                                                                                   : "";
    h << "<tr" << cls << "><td class=\"num\">" << c.entry->index << "</td><td><code>" << c.entry->id
      << "</code></td><td>" << html(c.entry->sweep) << "</td><td>" << html(c.entry->problem) << "</td><td>"
      << html(c.entry->method) << "</td><td>" << html(c.formulation) << "</td><td>" << html(c.entry->integrator)
      << "</td><td>" << html(case_setting(c)) << "</td><td class=\"num\">" << format_short(c.entry->t_end)
      << "</td><td>" << html(c.status) << "</td><td class=\"num\">" << seconds_text(c.wall_median)
      << "</td><td class=\"num\">" << c.ok_repeats << "/" << c.entry->repeats << "</td><td class=\"num\">"
      << html(c.steps) << "</td><td class=\"num\">" << sci(c.ref_error) << "</td><td class=\"num\">"
      << (std::isnan(c.ref_scd) ? "" : sci(c.ref_scd)) << "</td><td class=\"num\">" << sci(c.max_residual)
      << "</td><td class=\"num\">" << sci(c.drift) << "</td><td class=\"reason\">" << html(c.reason)
      << "</td></tr>\n";
  }
  h << "</table></div>\n";
  if (!not_applicable.empty()) {
    h << "<h3>Not applicable</h3>\n<p class=\"meta\">Combinations the harness rejected before running "
         "(status <code>invalid</code> in summary.csv).</p>\n<table><tr><th>problem / method / integrator</th>"
         "<th>cases</th><th>reason</th></tr>\n";
    for (const auto& [key, v] : not_applicable)
      h << "<tr><td>" << html(key) << "</td><td class=\"num\">" << v.first << "</td><td>" << html(v.second)
        << "</td></tr>\n";
    h << "</table>\n";
  }

  // Provenance and the matrix.
  h << "<h2 id=\"provenance\">Provenance</h2>\n<table>";
  if (prov.empty()) h << "<tr><td>no provenance.txt in this folder</td></tr>";
  for (const auto& [k, v] : prov) h << "<tr><th>" << html(k) << "</th><td>" << html(v) << "</td></tr>\n";
  h << "</table>\n<details><summary>The matrix (matrix.toml)</summary><pre>" << html(file_or_empty(dir + "/matrix.toml"))
    << "</pre></details>\n";
  for (const auto& w : result.warnings) h << "<p class=\"meta\">warning: " << html(w) << "</p>\n";
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
  result.html = dir + "/report.html";
  write_file_atomic(result.html, h.str());
  for (const auto& w : result.warnings) log << "report: warning: " << w << "\n";
  return result;
}

}  // namespace cstab

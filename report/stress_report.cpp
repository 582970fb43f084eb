#include "report/stress_report.hpp"

#include "methods/pair.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "core/format.hpp"
#include "io/csv.hpp"
#include "io/number.hpp"
#include "io/text.hpp"

namespace cstab {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string sci(double v) { return format_3g(v); }

// The wall time of a case's first repeat (what the stress tables show).
double first_wall(const CaseResult& c) { return c.repeats.empty() ? kNaN : c.repeats[0].wall_seconds; }

// A row's class: none if ok, "div" (highlighted) otherwise.
const char* row_class(bool ok) { return ok ? "" : " class=\"div\""; }

// The gain of a stiffness case: the value of the parameter its method
// declares as its gain (ParamSpec::role); NaN for a method without one, or
// one this binary does not know.
double gain_of(const CaseEntry& e) {
  for (const MethodInfo& m : all_methods()) {
    if (m.name != e.method) continue;
    const ParamSpec* gain = find_gain(m.params);
    if (!gain) return kNaN;
    const std::string key = gain->name + "=";
    const std::string& params = e.params;
    const size_t at = params.find(key);
    if (at == std::string::npos || (at != 0 && params[at - 1] != ';')) return kNaN;
    const size_t from = at + key.size();
    return parse_number(params.substr(from, params.find(';', at) - from));
  }
  return kNaN;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

void add_once(std::vector<std::string>& list, const std::string& s) {
  if (std::find(list.begin(), list.end(), s) == list.end()) list.push_back(s);
}

using Cases = std::vector<const CaseResult*>;

// The stress cases of a folder, by kind (complete, applicable cases only).
struct StressCases {
  Cases perturbed, long_runs, stiff, sharp;
};
StressCases stress_cases(const ResultsFolder& folder) {
  StressCases s;
  for (const CaseResult& c : folder.cases) {
    if (!c.complete || c.status == Status::kInvalid) continue;
    if (c.perturb > 0) s.perturbed.push_back(&c);
    if (starts_with(c.entry->sweep, "long")) s.long_runs.push_back(&c);
    if (starts_with(c.entry->sweep, "stiff")) s.stiff.push_back(&c);
    if (starts_with(c.entry->sweep, "sharp")) s.sharp.push_back(&c);
  }
  return s;
}

// ---- inconsistent starts ----

// DIR/stress_perturb.csv: one row per perturbed case.
void write_perturb_csv(const std::string& dir, const Cases& perturbed) {
  std::string csv =
      "problem,method,formulation,integrator,setting,params,perturb,status,initial_residual,max_residual,"
      "recovery_time,recovered,final_residual,case_id\n";
  for (const CaseResult* c : perturbed)
    csv += csv_line({c->entry->problem, c->entry->method, c->formulation, c->entry->integrator, c->entry->setting,
                     c->entry->params, format_short(c->perturb), status_name(c->status),
                     number_cell(c->initial_residual), number_cell(c->max_residual), number_cell(c->recovery_time),
                     c->recovered ? "yes" : "no", number_cell(c->final_residual), c->entry->id});
  write_file_atomic(dir + "/stress_perturb.csv", csv);
}

// The table at the perturbation nearest to 1e-3 (in log distance).
void perturb_table(std::ostream& h, const Cases& perturbed) {
  double shown = kNaN;
  for (const CaseResult* c : perturbed) {
    const double d = c->perturb;
    if (std::isnan(shown) || std::abs(std::log(d / 1e-3)) < std::abs(std::log(shown / 1e-3))) shown = d;
  }
  h << "<h3 id=\"stress-perturb\">Inconsistent starts</h3>\n<p class=\"meta\">Initial positions and velocities "
       "moved off the manifold by delta (<code>perturb</code>: y<sub>i</sub> += delta sin(i + 1) on the "
       "method's state). Recovery time: the first observed time after which the largest residual stays at or "
       "below the threshold (1e-10 by default) until t_end; empty if it never does. Table at delta = "
    << sci(shown) << "; every delta in <code>stress_perturb.csv</code>.</p>\n";
  h << "<table><tr><th>problem</th><th>method</th><th>integrator / setting</th><th>status</th>"
       "<th>initial residual</th><th>peak residual</th><th>recovery time</th><th>recovered</th></tr>\n";
  for (const CaseResult* c : perturbed) {
    if (c->perturb != shown) continue;
    const bool rec = c->recovered;
    h << "<tr" << row_class(rec) << "><td>" << html_escape(c->entry->problem) << "</td><td>"
      << html_escape(c->entry->method) << "</td><td>" << html_escape(c->entry->integrator + " " + c->entry->setting)
      << (c->entry->params.empty() ? "" : " ") << html_escape(c->entry->params) << "</td><td>"
      << html_escape(status_name(c->status)) << "</td><td class=\"num\">" << sci(c->initial_residual)
      << "</td><td class=\"num\">" << sci(c->max_residual) << "</td><td class=\"num\">"
      << (rec ? sci(c->recovery_time) : std::string("never")) << "</td><td>" << (rec ? "yes" : "no")
      << "</td></tr>\n";
  }
  h << "</table>\n";
}

// Per problem: peak residual and recovery time against delta, one curve per method.
void perturb_plots(const Cases& perturbed, StressSection& out) {
  std::vector<std::string> problems, methods;
  for (const CaseResult* c : perturbed) {
    add_once(problems, c->entry->problem);
    add_once(methods, c->entry->method);
  }
  for (const auto& problem : problems) {
    std::string data, lcs;
    size_t blocks = 0;
    for (size_t m = 0; m < methods.size(); ++m) {
      Cases pts;
      for (const CaseResult* c : perturbed)
        if (c->entry->problem == problem && c->entry->method == methods[m]) pts.push_back(c);
      if (pts.empty()) continue;
      std::stable_sort(pts.begin(), pts.end(),
                       [](const CaseResult* a, const CaseResult* b) { return a->perturb < b->perturb; });
      if (blocks++) data += "\n\n";
      data += gnuplot_data_title(methods[m] + " / " + pts[0]->entry->integrator) +
              " initial_residual max_residual recovery_time\n";
      lcs += ' ';
      lcs += std::to_string(m % 12 + 1);
      for (const CaseResult* c : pts)
        data += plot_cell(c->perturb) + " " + log_plot_cell(c->initial_residual) + " " + log_plot_cell(c->max_residual) +
                " " + (c->status == Status::kOk && c->recovered ? log_plot_cell(c->recovery_time) : "?") + "\n";
    }
    out.plots.push_back({"stress_perturb_" + problem, "stress_perturb.gp", data,
                         "; problem=" + gnuplot_string(problem) + "; lcs=" + gnuplot_string(lcs),
                         "Inconsistent starts on " + problem +
                             ": peak residual (left) and time to recover to 1e-10 (right) against the "
                             "perturbation delta, one curve per method; a missing point never recovered "
                             "(or diverged). Dashed: peak = initial residual."});
  }
}

// ---- near-singular motion ----

// A table of error, residual and the largest condition number per case.
void sharp_table(std::ostream& h, const Cases& sharp) {
  h << "<h3 id=\"stress-sharp\">Near-singular motion</h3>\n<p class=\"meta\">Sweeps named sharp*: error "
       "against the reference, largest residual and, for pesterev, the largest condition number of the "
       "reaction matrix over the series rows.</p>\n<table><tr><th>problem</th><th>method</th><th>integrator / "
       "setting</th><th>status</th><th>wall</th><th>ref error</th><th>max residual</th><th>max |dE|</th>"
       "<th>max cond</th></tr>\n";
  for (const CaseResult* c : sharp)
    h << "<tr" << row_class(c->status == Status::kOk) << "><td>" << html_escape(c->entry->problem) << "</td><td>"
      << html_escape(c->entry->method) << "</td><td>" << html_escape(c->entry->integrator + " " + c->entry->setting)
      << "</td><td>" << html_escape(status_name(c->status)) << "</td><td class=\"num\">" << sci(first_wall(*c))
      << "</td><td class=\"num\">" << sci(c->ref_error) << "</td><td class=\"num\">" << sci(c->max_residual)
      << "</td><td class=\"num\">" << sci(c->max_energy_drift) << "</td><td class=\"num\">" << sci(c->max_condition)
      << "</td></tr>\n";
  h << "</table>\n";
}

// ---- long horizons ----

double exponent_of(const CaseResult& c, const std::string& name) {
  for (const auto& [n, v] : c.integral_drift_exponents)
    if (n == name) return v;
  return kNaN;
}

// One case: its stress_long.csv line and its table row.
std::string long_row(std::ostream& h, const CaseResult& c, const std::vector<std::string>& integrals) {
  const double p = c.energy_drift_exponent;
  std::vector<std::string> cells = {c.entry->sweep, c.entry->problem, c.entry->method, c.entry->integrator,
                                    c.entry->setting, c.entry->params, format_short(c.entry->t_end),
                                    status_name(c.status), number_cell(first_wall(c)),
                                    number_cell(c.max_energy_drift), number_cell(p), drift_growth_class(p)};
  std::string others;
  for (const auto& name : integrals) {
    const double q = exponent_of(c, name);
    cells.push_back(number_cell(q));
    cells.push_back(drift_growth_class(q));
    if (!std::isnan(q))
      others += (others.empty() ? "" : ", ") + name + " " + sci(q) + " (" + drift_growth_class(q) + ")";
  }
  cells.push_back(c.entry->id);
  h << "<tr" << row_class(c.status == Status::kOk) << "><td>" << html_escape(c.entry->problem) << "</td><td>"
    << html_escape(c.entry->method) << "</td><td>"
    << html_escape(c.entry->integrator + " " + c.entry->setting + (c.entry->params.empty() ? "" : " " + c.entry->params))
    << "</td><td class=\"num\">" << format_short(c.entry->t_end) << "</td><td>" << html_escape(status_name(c.status))
    << "</td><td class=\"num\">" << sci(first_wall(c)) << "</td><td class=\"num\">" << sci(c.max_energy_drift)
    << "</td><td class=\"num\">" << sci(p) << "</td><td>" << drift_growth_class(p) << "</td><td>"
    << html_escape(others) << "</td></tr>\n";
  return csv_line(cells);
}

// Per sweep: one data block per finished run with an energy series.
struct LongPlots {
  std::vector<std::string> sweeps;
  std::map<std::string, std::string> data, lcs;
  std::map<std::string, size_t> blocks;
};

// The running max |E - E0| of a finished case from its series (decimated rows).
void add_long_series(LongPlots& plots, const std::string& dir, const CaseResult& c, SeriesUse& used) {
  if (c.status != Status::kOk) return;
  const CsvTable series = load_case_series(dir, *c.entry);
  if (series.column("t") < 0 || series.column("energy_drift") < 0) return;
  used[c.entry->id].insert({"t", "energy_drift"});
  const std::string& sweep = c.entry->sweep;
  add_once(plots.sweeps, sweep);
  std::string& data = plots.data[sweep];
  if (plots.blocks[sweep]++) data += "\n\n";
  data += gnuplot_data_title(c.entry->method + " (p = " + sci(c.energy_drift_exponent) + ")") +
          " running_max_abs_energy_drift\n";
  plots.lcs[sweep] += ' ';
  plots.lcs[sweep] += std::to_string((plots.blocks[sweep] - 1) % 12 + 1);
  double running = 0;
  for (size_t r = 0; r < series.rows.size(); ++r) {
    const double t = parse_number(series.get(r, "t")), e = std::abs(parse_number(series.get(r, "energy_drift")));
    if (std::isfinite(e)) running = std::max(running, e);
    if (t > 0) data += plot_cell(t) + " " + log_plot_cell(running) + "\n";
  }
}

// Drift growth exponents: DIR/stress_long.csv, the table, per sweep a picture.
void long_section(std::ostream& h, const ResultsFolder& folder, const Cases& long_runs, StressSection& out) {
  const std::vector<std::string>& integrals = folder.exponent_names;
  std::string csv = "sweep,problem,method,integrator,setting,params,t_end,status,wall_seconds,max_energy_drift,"
                    "energy_drift_exponent,energy_growth";
  for (const auto& name : integrals) csv += "," + name + "_drift_exponent," + name + "_growth";
  csv += ",case_id\n";
  h << "<h3 id=\"stress-long\">Long horizons</h3>\n<p class=\"meta\">Sweeps named long*: exponent p of "
       "max<sub>s&le;t</sub>|drift(s)| ~ t<sup>p</sup>, least squares in log-log over t in [10, t_end] "
       "(<code>energy_drift_exponent</code>, <code>&lt;integral&gt;_drift_exponent</code>); bounded "
       "p &lt; 0.25 &le; ~sqrt(t) &lt; 0.75 &le; ~linear &lt; 1.5.</p>\n<table><tr><th>problem</th><th>method</th>"
       "<th>integrator / setting</th><th>t_end</th><th>status</th><th>wall</th><th>max |dE|</th><th>energy p</th>"
       "<th>growth</th><th>other first integrals: p</th></tr>\n";
  LongPlots plots;
  for (const CaseResult* c : long_runs) {
    csv += long_row(h, *c, integrals);
    out.series_used[c->entry->id];  // kept even if unread
    add_long_series(plots, folder.dir, *c, out.series_used);
  }
  h << "</table>\n";
  write_file_atomic(folder.dir + "/stress_long.csv", csv);
  for (const auto& sweep : plots.sweeps)
    out.plots.push_back({"stress_" + sweep, "stress_long.gp", plots.data[sweep],
                         "; title=" + gnuplot_string(sweep) + "; lcs=" + gnuplot_string(plots.lcs[sweep]),
                         "Long horizon (" + sweep + "): running max |E(t) - E(0)| against t, log-log, one "
                         "curve per method (series rows); p is the fitted exponent over [10, t_end]; guides "
                         "t^{1/2} and t^1."});
}

// ---- stiffness ----

// Stiffness curves: method[formulation]/integrator setting, in first-appearance order.
struct StiffCurves {
  std::vector<std::string> names;
  std::map<std::string, Cases> of;
};

// DIR/stress_stiff.csv, and the cases grouped into curves.
StiffCurves write_stiff_csv(const std::string& dir, const Cases& stiff) {
  std::string csv = "problem,method,formulation,integrator,setting,gain,status,reason,wall_seconds,steps,"
                    "rhs_evals,ref_error,max_residual,case_id\n";
  StiffCurves curves;
  for (const CaseResult* c : stiff) {
    const double g = gain_of(*c->entry);
    csv += csv_line({c->entry->problem, c->entry->method, c->formulation, c->entry->integrator, c->entry->setting,
                     std::isnan(g) ? "" : format_short(g), status_name(c->status), c->reason,
                     number_cell(first_wall(*c)), count_cell(c->steps), count_cell(c->rhs_evals),
                     number_cell(c->ref_error), number_cell(c->max_residual), c->entry->id});
    const std::string curve = c->entry->problem + ": " + c->entry->method + "[" + c->formulation + "]/" +
                              c->entry->integrator + " " + c->entry->setting;
    if (!curves.of.count(curve)) curves.names.push_back(curve);
    curves.of[curve].push_back(c);
  }
  write_file_atomic(dir + "/stress_stiff.csv", csv);
  return curves;
}

// Wall time, error and residual against the gain: the table and one picture.
void stiff_section(std::ostream& h, const std::string& dir, const Cases& stiff, StressSection& out) {
  StiffCurves curves = write_stiff_csv(dir, stiff);
  h << "<h3 id=\"stress-stiff\">Stiffness</h3>\n<p class=\"meta\">Sweeps named stiff*: wall time "
       "(integration only), error at the reference time and largest residual against the feedback gain, per "
       "method[formulation]/integrator setting; gain-free formulations (IDA) are single rows. Every row in "
       "<code>stress_stiff.csv</code>.</p>\n<table><tr><th>curve</th><th>gain</th><th>status</th><th>wall</th>"
       "<th>steps</th><th>ref error</th><th>max residual</th></tr>\n";
  std::string data, lcs;
  size_t blocks = 0;
  bool has_ref = false;
  for (const auto& curve : curves.names) {
    Cases rows = curves.of[curve];
    std::stable_sort(rows.begin(), rows.end(), [](const CaseResult* a, const CaseResult* b) {
      return gain_of(*a->entry) < gain_of(*b->entry);
    });
    for (const CaseResult* c : rows)
      h << "<tr" << row_class(c->status == Status::kOk) << "><td>" << html_escape(curve)
        << "</td><td class=\"num\">" << sci(gain_of(*c->entry)) << "</td><td>"
        << html_escape(status_name(c->status)) << "</td><td class=\"num\">" << sci(first_wall(*c))
        << "</td><td class=\"num\">" << html_escape(count_cell(c->steps)) << "</td><td class=\"num\">"
        << sci(c->ref_error) << "</td><td class=\"num\">" << sci(c->max_residual) << "</td></tr>\n";
    if (std::isnan(gain_of(*rows[0]->entry))) continue;  // no gain axis
    if (blocks++) data += "\n\n";
    data += gnuplot_data_title(curve.substr(curve.find(": ") + 2)) + " wall_seconds ref_error max_residual\n";
    lcs += ' ';
    lcs += std::to_string((blocks - 1) % 12 + 1);
    for (const CaseResult* c : rows) {
      const bool ok = c->status == Status::kOk;
      has_ref = has_ref || (ok && c->ref_error > 0);
      data += plot_cell(gain_of(*c->entry)) + " " + (ok ? log_plot_cell(first_wall(*c)) : "?") + " " +
              (ok ? log_plot_cell(c->ref_error) : "?") + " " + (ok ? log_plot_cell(c->max_residual) : "?") + "\n";
    }
  }
  h << "</table>\n";
  if (blocks)
    out.plots.push_back({"stress_stiff", "stress_stiff.gp", data,
                         "; lcs=" + gnuplot_string(lcs) + "; has_ref=" + (has_ref ? "1" : "0"),
                         "Stiffness: wall time (left) and error at the reference time (right; the largest "
                         "residual where no case has a reference error) against the "
                         "feedback gain, log-log, one curve per method[formulation]/integrator setting; a "
                         "missing point diverged, failed or timed out."});
}

}  // namespace

std::string drift_growth_class(double p) {
  if (std::isnan(p)) return "";
  if (p < 0.25) return "bounded";
  if (p < 0.75) return "~sqrt(t)";
  if (p < 1.5) return "~linear";
  return "faster than linear";
}

StressSection build_stress_section(const ResultsFolder& folder) {
  StressSection out;
  std::ostringstream h;
  // Which cases are stress cases, by kind.
  const StressCases s = stress_cases(folder);
  // Inconsistent starts: table, CSV, per-problem pictures.
  if (!s.perturbed.empty()) {
    write_perturb_csv(folder.dir, s.perturbed);
    perturb_table(h, s.perturbed);
    perturb_plots(s.perturbed, out);
  }
  // Near-singular motion: a table.
  if (!s.sharp.empty()) sharp_table(h, s.sharp);
  // Long horizons: drift growth exponents.
  if (!s.long_runs.empty()) long_section(h, folder, s.long_runs, out);
  // Stiffness: cost and error against the gain.
  if (!s.stiff.empty()) stiff_section(h, folder.dir, s.stiff, out);
  out.empty = s.perturbed.empty() && s.sharp.empty() && s.long_runs.empty() && s.stiff.empty();
  out.html = h.str();
  return out;
}

}  // namespace cstab

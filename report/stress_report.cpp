#include "report/stress_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "io/csv.hpp"
#include "core/format.hpp"

namespace cstab {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double number(const std::string& s) {
  if (s.empty()) return kNaN;
  try {
    return std::stod(s);
  } catch (const std::exception&) {
    return kNaN;
  }
}

std::string esc(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

std::string sci(double v) { return format_3g(v); }

std::string line(const std::vector<std::string>& cells) {
  std::string s;
  for (size_t i = 0; i < cells.size(); ++i) s += (i ? "," : "") + csv_field(cells[i]);
  return s + "\n";
}

std::string plot_cell(double v) { return std::isfinite(v) && v > 0 ? format_exact(v) : "?"; }

std::string gp_quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

// One finished case: its manifest entry and its first summary row.
struct Row {
  const CaseEntry* entry;
  size_t r;
};

struct Lookup {
  const CsvTable& t;
  size_t r;
  const std::string& operator()(const char* col) const { return t.get(r, col); }
  double num(const char* col) const { return number(t.get(r, col)); }
};

// The gain of a stiffness case: its lambda, else alpha (baumgarte), else dt.
double gain_of(const std::string& params) {
  for (const char* key : {"lambda=", "alpha="}) {
    const size_t at = params.find(key);
    if (at != std::string::npos && (at == 0 || params[at - 1] == ';'))
      return number(params.substr(at + std::string(key).size(), params.find(';', at) - at - std::string(key).size()));
  }
  return kNaN;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::string drift_growth_class(double p) {
  if (std::isnan(p)) return "";
  if (p < 0.25) return "bounded";
  if (p < 0.75) return "~sqrt(t)";
  if (p < 1.5) return "~linear";
  return "faster than linear";
}

StressSection build_stress_section(const std::string& dir, const std::vector<CaseEntry>& entries,
                                   const CsvTable& summary) {
  StressSection out;
  std::map<std::string, size_t> first_row;
  const int id_col = summary.column("case_id");
  for (size_t r = 0; r < summary.rows.size(); ++r)
    if (id_col >= 0 && size_t(id_col) < summary.rows[r].size()) first_row.emplace(summary.rows[r][size_t(id_col)], r);
  std::vector<Row> perturbed, long_runs, stiff, sharp;
  for (const auto& e : entries) {
    auto it = first_row.find(e.id);
    if (it == first_row.end()) continue;
    const Lookup get{summary, it->second};
    if (get("status") == "invalid") continue;
    if (number(get("perturb")) > 0) perturbed.push_back({&e, it->second});
    if (starts_with(e.sweep, "long")) long_runs.push_back({&e, it->second});
    if (starts_with(e.sweep, "stiff")) stiff.push_back({&e, it->second});
    if (starts_with(e.sweep, "sharp")) sharp.push_back({&e, it->second});
  }
  std::ostringstream h;

  // ---- inconsistent starts ----
  if (!perturbed.empty()) {
    out.empty = false;
    std::string csv =
        "problem,method,formulation,integrator,setting,params,perturb,status,initial_residual,max_residual,"
        "recovery_time,recovered,final_residual,case_id\n";
    std::vector<std::string> problems, methods;
    for (const Row& c : perturbed) {
      const Lookup get{summary, c.r};
      csv += line({c.entry->problem, c.entry->method, get("formulation"), c.entry->integrator, c.entry->setting,
                   c.entry->params, get("perturb"), get("status"), get("initial_residual"), get("max_residual"),
                   get("recovery_time"), get("recovered"), get("final_residual"), c.entry->id});
      if (std::find(problems.begin(), problems.end(), c.entry->problem) == problems.end())
        problems.push_back(c.entry->problem);
      if (std::find(methods.begin(), methods.end(), c.entry->method) == methods.end())
        methods.push_back(c.entry->method);
    }
    write_file_atomic(dir + "/stress_perturb.csv", csv);
    // The table at the perturbation nearest to 1e-3 (in log distance).
    double shown = kNaN;
    for (const Row& c : perturbed) {
      const double d = number(summary.get(c.r, "perturb"));
      if (std::isnan(shown) || std::abs(std::log(d / 1e-3)) < std::abs(std::log(shown / 1e-3))) shown = d;
    }
    h << "<h3 id=\"stress-perturb\">Inconsistent starts</h3>\n<p class=\"meta\">Initial positions and velocities "
         "moved off the manifold by delta (<code>perturb</code>: y<sub>i</sub> += delta sin(i + 1) on the "
         "method's state). Recovery time: the first observed time after which the largest residual stays at or "
         "below the threshold (1e-10 by default) until t_end; empty if it never does. Table at delta = "
      << sci(shown) << "; every delta in <code>stress_perturb.csv</code>.</p>\n";
    h << "<table><tr><th>problem</th><th>method</th><th>integrator / setting</th><th>status</th>"
         "<th>initial residual</th><th>peak residual</th><th>recovery time</th><th>recovered</th></tr>\n";
    for (const Row& c : perturbed) {
      const Lookup get{summary, c.r};
      if (get.num("perturb") != shown) continue;
      const bool rec = get("recovered") == "yes";
      h << "<tr" << (rec ? "" : " class=\"div\"") << "><td>" << esc(c.entry->problem) << "</td><td>"
        << esc(c.entry->method) << "</td><td>" << esc(c.entry->integrator + " " + c.entry->setting)
        << (c.entry->params.empty() ? "" : " " + esc(c.entry->params)) << "</td><td>" << esc(get("status"))
        << "</td><td class=\"num\">" << sci(get.num("initial_residual")) << "</td><td class=\"num\">"
        << sci(get.num("max_residual")) << "</td><td class=\"num\">"
        << (rec ? sci(get.num("recovery_time")) : std::string("never")) << "</td><td>" << (rec ? "yes" : "no")
        << "</td></tr>\n";
    }
    h << "</table>\n";
    for (const auto& problem : problems) {
      std::string data, lcs;
      size_t blocks = 0;
      for (size_t m = 0; m < methods.size(); ++m) {
        std::vector<const Row*> pts;
        for (const Row& c : perturbed)
          if (c.entry->problem == problem && c.entry->method == methods[m]) pts.push_back(&c);
        if (pts.empty()) continue;
        std::stable_sort(pts.begin(), pts.end(), [&](const Row* a, const Row* b) {
          return number(summary.get(a->r, "perturb")) < number(summary.get(b->r, "perturb"));
        });
        if (blocks++) data += "\n\n";
        data += gp_quote(methods[m] + " / " + pts[0]->entry->integrator) + " initial_residual max_residual recovery_time\n";
        lcs += " " + std::to_string(m % 12 + 1);
        for (const Row* c : pts) {
          const Lookup get{summary, c->r};
          const bool ok = get("status") == "ok";
          data += format_exact(get.num("perturb")) + " " + plot_cell(get.num("initial_residual")) + " " +
                  plot_cell(get.num("max_residual")) + " " +
                  (ok && get("recovered") == "yes" ? plot_cell(get.num("recovery_time")) : "?") + "\n";
        }
      }
      out.plots.push_back({"stress_perturb_" + problem, "stress_perturb.gp", data,
                           "; problem=" + gp_quote(problem) + "; lcs=" + gp_quote(lcs),
                           "Inconsistent starts on " + problem +
                               ": peak residual (left) and time to recover to 1e-10 (right) against the "
                               "perturbation delta, one curve per method; a missing point never recovered "
                               "(or diverged). Dashed: peak = initial residual."});
    }
  }

  // ---- near-singular motion ----
  if (!sharp.empty()) {
    out.empty = false;
    h << "<h3 id=\"stress-sharp\">Near-singular motion</h3>\n<p class=\"meta\">Sweeps named sharp*: error "
         "against the reference, largest residual and, for pesterev, the largest condition number of the "
         "reaction matrix over the series rows.</p>\n<table><tr><th>problem</th><th>method</th><th>integrator / "
         "setting</th><th>status</th><th>wall</th><th>ref error</th><th>max residual</th><th>max |dE|</th>"
         "<th>max cond</th></tr>\n";
    for (const Row& c : sharp) {
      const Lookup get{summary, c.r};
      h << "<tr" << (get("status") == "ok" ? "" : " class=\"div\"") << "><td>" << esc(c.entry->problem)
        << "</td><td>" << esc(c.entry->method) << "</td><td>" << esc(c.entry->integrator + " " + c.entry->setting)
        << "</td><td>" << esc(get("status")) << "</td><td class=\"num\">" << sci(get.num("wall_seconds"))
        << "</td><td class=\"num\">" << sci(get.num("ref_error")) << "</td><td class=\"num\">"
        << sci(get.num("max_residual")) << "</td><td class=\"num\">" << sci(get.num("max_energy_drift"))
        << "</td><td class=\"num\">" << sci(get.num("max_condition")) << "</td></tr>\n";
    }
    h << "</table>\n";
  }

  // ---- long horizons ----
  if (!long_runs.empty()) {
    out.empty = false;
    std::vector<std::string> integral_cols;
    for (const auto& col : summary.header)
      if (col.size() > 15 && col.compare(col.size() - 15, 15, "_drift_exponent") == 0 &&
          col != "energy_drift_exponent")
        integral_cols.push_back(col);
    std::string csv = "sweep,problem,method,integrator,setting,params,t_end,status,wall_seconds,max_energy_drift,"
                      "energy_drift_exponent,energy_growth";
    for (const auto& col : integral_cols) csv += "," + col + "," + col.substr(0, col.size() - 15) + "_growth";
    csv += ",case_id\n";
    h << "<h3 id=\"stress-long\">Long horizons</h3>\n<p class=\"meta\">Sweeps named long*: exponent p of "
         "max<sub>s&le;t</sub>|drift(s)| ~ t<sup>p</sup>, least squares in log-log over t in [10, t_end] "
         "(<code>energy_drift_exponent</code>, <code>&lt;integral&gt;_drift_exponent</code>); bounded "
         "p &lt; 0.25 &le; ~sqrt(t) &lt; 0.75 &le; ~linear &lt; 1.5.</p>\n<table><tr><th>problem</th><th>method</th>"
         "<th>integrator / setting</th><th>t_end</th><th>status</th><th>wall</th><th>max |dE|</th><th>energy p</th>"
         "<th>growth</th><th>other first integrals: p</th></tr>\n";
    std::map<std::string, std::string> data_of, lcs_of;  // per sweep
    std::map<std::string, size_t> blocks_of;
    std::vector<std::string> sweeps;
    for (const Row& c : long_runs) {
      const Lookup get{summary, c.r};
      const double p = get.num("energy_drift_exponent");
      std::vector<std::string> cells = {c.entry->sweep, c.entry->problem, c.entry->method, c.entry->integrator,
                                        c.entry->setting, c.entry->params, format_short(c.entry->t_end),
                                        get("status"), get("wall_seconds"), get("max_energy_drift"),
                                        get("energy_drift_exponent"), drift_growth_class(p)};
      std::string others;
      for (const auto& col : integral_cols) {
        const double q = get.num(col.c_str());
        cells.push_back(get(col.c_str()));
        cells.push_back(drift_growth_class(q));
        if (!std::isnan(q))
          others += (others.empty() ? "" : ", ") + col.substr(0, col.size() - 15) + " " + sci(q) + " (" +
                    drift_growth_class(q) + ")";
      }
      cells.push_back(c.entry->id);
      csv += line(cells);
      h << "<tr" << (get("status") == "ok" ? "" : " class=\"div\"") << "><td>" << esc(c.entry->problem)
        << "</td><td>" << esc(c.entry->method) << "</td><td>"
        << esc(c.entry->integrator + " " + c.entry->setting + (c.entry->params.empty() ? "" : " " + c.entry->params))
        << "</td><td class=\"num\">" << format_short(c.entry->t_end) << "</td><td>" << esc(get("status"))
        << "</td><td class=\"num\">" << sci(get.num("wall_seconds")) << "</td><td class=\"num\">"
        << sci(get.num("max_energy_drift")) << "</td><td class=\"num\">" << sci(p) << "</td><td>"
        << drift_growth_class(p) << "</td><td>" << esc(others) << "</td></tr>\n";
      // Running max |E - E0| from the series (decimated rows).
      if (get("status") != "ok") continue;
      CsvTable series;
      try {
        series = read_csv(dir + "/cases/" + c.entry->id + "/series.csv");
      } catch (const std::exception&) {
        continue;
      }
      const int tc = series.column("t"), ec = series.column("energy_drift");
      if (tc < 0 || ec < 0) continue;
      if (std::find(sweeps.begin(), sweeps.end(), c.entry->sweep) == sweeps.end()) sweeps.push_back(c.entry->sweep);
      std::string& data = data_of[c.entry->sweep];
      if (blocks_of[c.entry->sweep]++) data += "\n\n";
      data += gp_quote(c.entry->method + " (p = " + sci(p) + ")") + " running_max_abs_energy_drift\n";
      lcs_of[c.entry->sweep] += " " + std::to_string((blocks_of[c.entry->sweep] - 1) % 12 + 1);
      double running = 0;
      for (size_t r = 0; r < series.rows.size(); ++r) {
        const double t = number(series.get(r, "t")), e = std::abs(number(series.get(r, "energy_drift")));
        if (std::isfinite(e)) running = std::max(running, e);
        if (t > 0) data += format_exact(t) + " " + plot_cell(running) + "\n";
      }
    }
    h << "</table>\n";
    write_file_atomic(dir + "/stress_long.csv", csv);
    for (const auto& sweep : sweeps)
      out.plots.push_back({"stress_" + sweep, "stress_long.gp", data_of[sweep],
                           "; title=" + gp_quote(sweep) + "; lcs=" + gp_quote(lcs_of[sweep]),
                           "Long horizon (" + sweep + "): running max |E(t) - E(0)| against t, log-log, one "
                           "curve per method (series rows); p is the fitted exponent over [10, t_end]; guides "
                           "t^{1/2} and t^1."});
  }

  // ---- stiffness ----
  if (!stiff.empty()) {
    out.empty = false;
    std::string csv = "problem,method,formulation,integrator,setting,gain,status,reason,wall_seconds,steps,"
                      "rhs_evals,ref_error,max_residual,case_id\n";
    std::vector<std::string> curves;
    std::map<std::string, std::vector<const Row*>> of_curve;
    std::string problem;
    for (const Row& c : stiff) {
      const Lookup get{summary, c.r};
      const double g = gain_of(c.entry->params);
      csv += line({c.entry->problem, c.entry->method, get("formulation"), c.entry->integrator, c.entry->setting,
                   std::isnan(g) ? "" : format_short(g), get("status"), get("reason"), get("wall_seconds"),
                   get("steps"), get("rhs_evals"), get("ref_error"), get("max_residual"), c.entry->id});
      const std::string curve =
          c.entry->problem + ": " + c.entry->method + "[" + get("formulation") + "]/" + c.entry->integrator + " " + c.entry->setting;
      if (!of_curve.count(curve)) curves.push_back(curve);
      of_curve[curve].push_back(&c);
    }
    write_file_atomic(dir + "/stress_stiff.csv", csv);
    h << "<h3 id=\"stress-stiff\">Stiffness</h3>\n<p class=\"meta\">Sweeps named stiff*: wall time "
         "(integration only), error at the reference time and largest residual against the feedback gain, per "
         "method[formulation]/integrator setting; gain-free formulations (IDA) are single rows. Every row in "
         "<code>stress_stiff.csv</code>.</p>\n<table><tr><th>curve</th><th>gain</th><th>status</th><th>wall</th>"
         "<th>steps</th><th>ref error</th><th>max residual</th></tr>\n";
    std::string data, lcs;
    size_t blocks = 0;
    bool has_ref = false;
    for (const auto& curve : curves) {
      auto rows = of_curve[curve];
      std::stable_sort(rows.begin(), rows.end(), [](const Row* a, const Row* b) {
        return gain_of(a->entry->params) < gain_of(b->entry->params);
      });
      for (const Row* c : rows) {
        const Lookup get{summary, c->r};
        h << "<tr" << (get("status") == "ok" ? "" : " class=\"div\"") << "><td>" << esc(curve)
          << "</td><td class=\"num\">" << sci(gain_of(c->entry->params)) << "</td><td>" << esc(get("status"))
          << "</td><td class=\"num\">" << sci(get.num("wall_seconds")) << "</td><td class=\"num\">"
          << esc(get("steps")) << "</td><td class=\"num\">" << sci(get.num("ref_error")) << "</td><td class=\"num\">"
          << sci(get.num("max_residual")) << "</td></tr>\n";
      }
      if (std::isnan(gain_of(rows[0]->entry->params))) continue;  // no gain axis
      if (blocks++) data += "\n\n";
      data += gp_quote(curve.substr(curve.find(": ") + 2)) + " wall_seconds ref_error max_residual\n";
      lcs += " " + std::to_string((blocks - 1) % 12 + 1);
      for (const Row* c : rows) {
        const Lookup get{summary, c->r};
        const bool ok = get("status") == "ok";
        has_ref = has_ref || (ok && get.num("ref_error") > 0);
        data += format_exact(gain_of(c->entry->params)) + " " + (ok ? plot_cell(get.num("wall_seconds")) : "?") +
                " " + (ok ? plot_cell(get.num("ref_error")) : "?") + " " +
                (ok ? plot_cell(get.num("max_residual")) : "?") + "\n";
      }
    }
    h << "</table>\n";
    if (blocks)
      out.plots.push_back({"stress_stiff", "stress_stiff.gp", data,
                           "; lcs=" + gp_quote(lcs) + "; has_ref=" + (has_ref ? "1" : "0"),
                           "Stiffness: wall time (left) and error at the reference time (right; the largest "
                           "residual where no case has a reference error) against the "
                           "feedback gain, log-log, one curve per method[formulation]/integrator setting; a "
                           "missing point diverged, failed or timed out."});
  }
  out.html = h.str();
  return out;
}

}  // namespace cstab

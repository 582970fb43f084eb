#include "report/scaling.hpp"

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

// The accuracy levels a study's fixed-accuracy cost may be taken at, loosest first.
const std::vector<double>& scaling_levels() {
  static const std::vector<double> levels = {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12};
  return levels;
}

struct Point {
  double size = kNaN;
  std::vector<const CaseResult*> cases;  // every case of the curve at this size
  double per_step = kNaN;                // median of wall / steps over the finished ones
  const CaseResult* at_level = nullptr;  // the fastest finished case within the level
};

struct Curve {
  std::string name;
  std::vector<Point> points;  // by size
  double step_exponent = kNaN, level_exponent = kNaN;
};

struct Study {
  std::string problem, param;
  std::vector<Curve> curves;  // first-appearance order
  double level = kNaN;
};

bool finished(const CaseResult& c) { return c.ok() && std::isfinite(c.wall_median) && c.steps > 0; }

// "N=40" -> ("N", 40); nullopt-like (empty name) unless exactly one numeric parameter.
std::pair<std::string, double> single_param(const std::string& problem_params) {
  const size_t eq = problem_params.find('=');
  if (problem_params.empty() || problem_params.find(';') != std::string::npos || eq == std::string::npos) return {};
  const double v = parse_number(problem_params.substr(eq + 1));
  if (!(v > 0) || !std::isfinite(v)) return {};
  return {problem_params.substr(0, eq), v};
}

std::string curve_name(const CaseResult& c) {
  const CaseEntry& e = *c.entry;
  return e.method + (c.formulation.empty() ? "" : "[" + c.formulation + "]") + "/" + e.integrator +
         (e.params.empty() ? "" : " " + e.params);
}

// The studies of a folder: cases grouped by (problem, parameter), then by curve and size.
std::vector<Study> collect(const ResultsFolder& folder) {
  std::vector<Study> studies;
  for (const CaseResult& c : folder.cases) {
    if (!c.complete || c.status == Status::kInvalid || c.entry->tuned() || c.entry->integrator == "external") continue;
    // (Named copies, not a structured binding: lambdas capture those only
    // from clang 16 on.)
    const auto single = single_param(c.entry->problem_params);
    const auto& param = single.first;
    const auto size = single.second;
    if (param.empty()) continue;
    auto s = std::find_if(studies.begin(), studies.end(),
                          [&](const Study& x) { return x.problem == c.entry->problem && x.param == param; });
    if (s == studies.end()) s = studies.insert(studies.end(), Study{c.entry->problem, param, {}, kNaN});
    const std::string name = curve_name(c);
    auto cv = std::find_if(s->curves.begin(), s->curves.end(), [&](const Curve& x) { return x.name == name; });
    if (cv == s->curves.end()) cv = s->curves.insert(s->curves.end(), Curve{name, {}, kNaN, kNaN});
    auto pt = std::find_if(cv->points.begin(), cv->points.end(), [&](const Point& x) { return x.size == size; });
    if (pt == cv->points.end()) pt = cv->points.insert(cv->points.end(), Point{size, {}, kNaN, nullptr});
    pt->cases.push_back(&c);
  }
  return studies;
}

// Per point: the median cost per step and the fastest case within `level`.
void measure(Curve& curve, double level) {
  std::sort(curve.points.begin(), curve.points.end(), [](const Point& a, const Point& b) { return a.size < b.size; });
  std::vector<std::pair<double, double>> per_step, at_level;
  for (Point& p : curve.points) {
    std::vector<double> costs;
    p.at_level = nullptr;
    for (const CaseResult* c : p.cases) {
      if (!finished(*c)) continue;
      costs.push_back(c->wall_median / double(c->steps));
      if (std::isfinite(level) && c->ref_error <= level && (!p.at_level || c->wall_median < p.at_level->wall_median))
        p.at_level = c;
    }
    p.per_step = median(costs);
    per_step.push_back({p.size, p.per_step});
    if (p.at_level) at_level.push_back({p.size, p.at_level->wall_median});
  }
  curve.step_exponent = per_step.size() >= 3 ? fit_log_log_slope(per_step) : kNaN;
  curve.level_exponent = at_level.size() >= 3 ? fit_log_log_slope(at_level) : kNaN;
}

int sizes_within(const Curve& curve, double level) {
  int n = 0;
  for (const Point& p : curve.points)
    n += std::any_of(p.cases.begin(), p.cases.end(),
                     [&](const CaseResult* c) { return finished(*c) && c->ref_error <= level; });
  return n;
}

// The tightest level some curve reaches at three sizes; NaN if none.
double study_level(const Study& s) {
  double level = kNaN;
  for (double l : scaling_levels())
    for (const Curve& c : s.curves)
      if (sizes_within(c, l) >= 3) level = l;
  return level;
}

int finished_sizes(const Curve& curve) {
  int n = 0;
  for (const Point& p : curve.points)
    n += std::any_of(p.cases.begin(), p.cases.end(), [](const CaseResult* c) { return finished(*c); });
  return n;
}

// Keeps the curves with three finished sizes or more, measured; names the
// others in `dropped`.
void finish(Study& s, std::vector<std::string>& dropped) {
  for (const Curve& c : s.curves)
    if (c.points.size() >= 3 && finished_sizes(c) < 3)
      dropped.push_back(s.problem + ": " + c.name + " (" + std::to_string(finished_sizes(c)) + " of " +
                        std::to_string(c.points.size()) + " sizes finished)");
  s.curves.erase(std::remove_if(s.curves.begin(), s.curves.end(), [](const Curve& c) { return finished_sizes(c) < 3; }),
                 s.curves.end());
  for (Curve& c : s.curves)
    c.points.erase(std::remove_if(c.points.begin(), c.points.end(),
                                  [](const Point& p) {
                                    return std::none_of(p.cases.begin(), p.cases.end(),
                                                        [](const CaseResult* x) { return finished(*x); });
                                  }),
                   c.points.end());
  s.level = study_level(s);
  for (Curve& c : s.curves) measure(c, s.level);
}

std::string exponent_text(double p) { return std::isnan(p) ? "" : format_short(std::round(p * 100) / 100); }

std::string write_csv(const std::string& dir, const std::vector<Study>& studies) {
  std::string csv =
      "problem,parameter,curve,size,cases,finished,cost_per_step_s,level,wall_at_level_s,setting_at_level,"
      "step_exponent,level_exponent\n";
  for (const Study& s : studies)
    for (const Curve& c : s.curves)
      for (const Point& p : c.points) {
        const long done =
            std::count_if(p.cases.begin(), p.cases.end(), [](const CaseResult* x) { return finished(*x); });
        csv += csv_line({s.problem, s.param, c.name, format_short(p.size), std::to_string(p.cases.size()),
                         std::to_string(done), number_cell(p.per_step), number_cell(s.level),
                         number_cell(p.at_level ? p.at_level->wall_median : kNaN),
                         p.at_level ? p.at_level->entry->setting : "", number_cell(c.step_exponent),
                         number_cell(c.level_exponent)});
      }
  write_file_atomic(dir + "/scaling.csv", csv);
  return csv;
}

void study_table(std::ostream& h, const Study& s) {
  const std::string level = std::isnan(s.level) ? "" : format_short(s.level);
  h << "<h3 id=\"scaling-" << html_escape(s.problem) << "\">" << html_escape(s.problem) << ": cost against "
    << html_escape(s.param) << "</h3>\n<table><tr><th>curve</th><th>" << html_escape(s.param)
    << "</th><th>cost per step</th><th>exponent</th>";
  if (!level.empty()) h << "<th>wall at error &le; " << level << "</th><th>exponent</th>";
  h << "</tr>\n";
  for (const Curve& c : s.curves) {
    const Point& lo = c.points.front();
    const Point& hi = c.points.back();
    h << "<tr><td>" << html_escape(c.name) << "</td><td class=\"num\">" << format_short(lo.size) << " .. "
      << format_short(hi.size) << "</td><td class=\"num\">" << format_3g(lo.per_step) << " .. "
      << format_3g(hi.per_step) << " s</td><td class=\"num\">" << exponent_text(c.step_exponent) << "</td>";
    if (!level.empty()) {
      std::string walls;
      for (const Point& p : c.points) {
        if (!walls.empty()) walls += ", ";
        walls += p.at_level ? format_3g(p.at_level->wall_median) : "-";
      }
      h << "<td class=\"num\">" << walls << " s</td><td class=\"num\">" << exponent_text(c.level_exponent) << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";
}

StressPlot study_plot(const Study& s) {
  std::string data, lcs;
  for (size_t i = 0; i < s.curves.size(); ++i) {
    const Curve& c = s.curves[i];
    if (i) data += "\n\n";
    // The label ends in the fitted exponents (GCC 12 warns, wrongly, of
    // overlapping copies in `"literal" + std::string&&`: appended instead).
    std::string title = c.name + " (p = ";
    title += std::isnan(c.step_exponent) ? "-" : exponent_text(c.step_exponent);
    if (!std::isnan(s.level)) {
      title += "; ";
      title += std::isnan(c.level_exponent) ? "-" : exponent_text(c.level_exponent);
    }
    data += gnuplot_data_title(title + ")") + " cost_per_step wall_at_level\n";
    lcs += ' ';
    lcs += std::to_string(i % 12 + 1);
    for (const Point& p : c.points)
      data += plot_cell(p.size) + " " + log_plot_cell(p.per_step) + " " +
              (p.at_level ? log_plot_cell(p.at_level->wall_median) : std::string("?")) + "\n";
  }
  const std::string name = s.problem + "_scaling";
  return {
      name, "scaling.gp", data,
      "; lcs=" + gnuplot_string(lcs) + "; param=" + gnuplot_string(s.param) + "; problem=" + gnuplot_string(s.problem) +
          "; level=" + gnuplot_string(std::isnan(s.level) ? "" : format_short(s.level)),
      "Scaling of " + s.problem + ": cost per step (left) and wall time at error <= " +
          (std::isnan(s.level) ? std::string("(no level)") : format_short(s.level)) + " (right) against " + s.param +
          ", log-log, one curve per method/integrator; p in the legend is the fitted exponent "
          "(per step; at the level)."};
}

}  // namespace

double fit_log_log_slope(const std::vector<std::pair<double, double>>& points) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& [x, y] : points) {
    if (!(x > 0) || !(y > 0) || !std::isfinite(x) || !std::isfinite(y)) continue;
    const double lx = std::log(x), ly = std::log(y);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    ++n;
  }
  const double den = n * sxx - sx * sx;
  if (n < 2 || !(std::abs(den) > 1e-12)) return kNaN;
  return (n * sxy - sx * sy) / den;
}

ScalingSection build_scaling_section(const ResultsFolder& folder) {
  ScalingSection out;
  std::vector<Study> studies = collect(folder);
  std::vector<std::string> dropped;
  for (Study& s : studies) finish(s, dropped);
  studies.erase(std::remove_if(studies.begin(), studies.end(), [](const Study& s) { return s.curves.empty(); }),
                studies.end());
  if (studies.empty() && dropped.empty()) return out;
  out.empty = false;
  write_csv(folder.dir, studies);
  std::ostringstream h;
  h << "<p class=\"meta\">Cases of one problem that differ in one problem parameter (a matrix's "
       "<code>problem_param.N = [...]</code>), per method/integrator with three sizes or more: the cost per "
       "step (median over the curve's finished cases at that size of wall time / steps) and the wall time of "
       "its fastest case within a fixed error against the reference (the tightest level some curve reaches at "
       "three sizes), each fitted as cost ~ size<sup>p</sup> by least squares on log-log. Every point in "
       "<code>scaling.csv</code>.</p>\n";
  if (!dropped.empty()) {
    h << "<p class=\"meta\">Left out, fewer than three sizes with a finished case (the others diverged, failed or "
         "timed out):";
    for (size_t i = 0; i < dropped.size(); ++i) h << (i ? "; " : " ") << html_escape(dropped[i]);
    h << ".</p>\n";
  }
  for (const Study& s : studies) {
    study_table(h, s);
    out.plots.push_back(study_plot(s));
  }
  out.html = h.str();
  return out;
}

}  // namespace cstab

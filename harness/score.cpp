#include "harness/score.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "core/format.hpp"
#include "harness/recorder.hpp"
#include "io/csv.hpp"
#include "io/gzip.hpp"
#include "io/number.hpp"

namespace cstab {

namespace {

std::string file_text(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw UsageError(path + ": no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError(path + ": cannot open");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const bool gz = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  if (!gz) return bytes.str();
  try {
    return gzip_decompress(bytes.str(), size_t(1) << 34);
  } catch (const std::exception& e) {
    throw UsageError(path + ": " + e.what());
  }
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") + 1 - b);
}

// One line's cells with the 1-based column where each starts.
struct Cells {
  std::vector<std::string> text;
  std::vector<size_t> column;
};

Cells split(const std::string& line) {
  Cells c;
  size_t at = 0;
  while (true) {
    const size_t comma = line.find(',', at);
    c.text.push_back(trim(line.substr(at, comma == std::string::npos ? std::string::npos : comma - at)));
    c.column.push_back(at + 1);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return c;
}

// Columns a cstab series.csv adds to the coordinates: not states, ignored.
bool derived_column(const std::string& name, const ProblemInfo& info) {
  if (name.rfind("residual_", 0) == 0 || name == "energy_drift" || name == "cond") return true;
  return std::any_of(info.first_integrals.begin(), info.first_integrals.end(),
                     [&](const std::string& fi) { return name == fi + "_drift"; });
}

// Second-order derivative of x at every row (non-uniform 3-point formulas;
// one-sided at the ends).
void difference(const std::vector<double>& t, const std::vector<double>& x, std::vector<double>& dx) {
  const size_t n = t.size();
  dx.assign(n, 0);
  auto three_point = [&](size_t a, size_t b, size_t c, size_t at) {
    // Derivative at t[at] of the parabola through rows a < b < c.
    const double ta = t[a], tb = t[b], tc = t[c], s = t[at];
    const double la = ((s - tb) + (s - tc)) / ((ta - tb) * (ta - tc));
    const double lb = ((s - ta) + (s - tc)) / ((tb - ta) * (tb - tc));
    const double lc = ((s - ta) + (s - tb)) / ((tc - ta) * (tc - tb));
    return la * x[a] + lb * x[b] + lc * x[c];
  };
  for (size_t i = 0; i < n; ++i) {
    const size_t mid = std::clamp<size_t>(i, 1, n - 2);
    dx[i] = three_point(mid - 1, mid, mid + 1, i);
  }
}

struct Header {
  std::vector<int> coordinate_of_cell;  // -1: t; -2: ignored; else the coordinate
  std::vector<int> cell_of_coordinate;  // -1: differenced
  std::vector<int> position_of_coordinate;  // for a differenced one: its position coordinate
};

Header read_header(const std::string& where, const std::string& line, const ProblemInfo& info, Trajectory& tr) {
  const Cells cells = split(line);
  const size_t nc = info.coordinates.size();
  std::map<std::string, int> index;
  for (size_t i = 0; i < nc; ++i) index[info.coordinates[i]] = int(i);
  Header h;
  h.cell_of_coordinate.assign(nc, -1);
  h.position_of_coordinate.assign(nc, -1);
  bool has_t = false;
  std::map<std::string, size_t> seen;
  for (size_t k = 0; k < cells.text.size(); ++k) {
    const std::string& name = cells.text[k];
    const std::string at = where + ":" + std::to_string(cells.column[k]) + ": ";
    if (seen.count(name)) throw UsageError(at + "column '" + name + "' appears twice");
    seen[name] = k;
    if (name == "t") {
      has_t = true;
      h.coordinate_of_cell.push_back(-1);
    } else if (auto it = index.find(name); it != index.end()) {
      h.coordinate_of_cell.push_back(it->second);
      h.cell_of_coordinate[it->second] = int(k);
    } else if (derived_column(name, info)) {
      h.coordinate_of_cell.push_back(-2);
      tr.ignored.push_back(name);
    } else {
      std::string names;
      for (const auto& c : info.coordinates) names += (names.empty() ? "" : ",") + c;
      throw UsageError(at + "unknown column '" + name + "': problem '" + info.name + "' has t," + names +
                       " (is this a trajectory of another problem?)");
    }
  }
  if (!has_t) throw UsageError(where + ": no column 't'");
  for (size_t i = 0; i < nc; ++i) {
    if (h.cell_of_coordinate[i] >= 0) continue;
    const std::string& name = info.coordinates[i];
    const bool velocity = name.size() > 3 && name.compare(name.size() - 3, 3, "dot") == 0;
    const auto pos = velocity ? index.find(name.substr(0, name.size() - 3)) : index.end();
    if (pos == index.end() || h.cell_of_coordinate[pos->second] < 0)
      throw UsageError(where + ": missing column '" + name + "' of problem '" + info.name + "'");
    h.position_of_coordinate[i] = pos->second;
    tr.differenced.push_back(name);
  }
  return h;
}

}  // namespace

Trajectory read_trajectory(const std::string& path, const ProblemInfo& info) {
  const std::string text = file_text(path);
  Trajectory tr;
  std::istringstream in(text);
  std::string line;
  size_t line_no = 0;
  Header header;
  bool have_header = false;
  const size_t nc = info.coordinates.size();
  std::vector<double> row(nc);
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!have_header && !line.empty() && line[0] == '#') {
      const size_t eq = line.find('=');
      if (eq != std::string::npos && trim(line.substr(1, eq - 1)) == "wall_seconds") {
        const std::string v = trim(line.substr(eq + 1));
        double w = 0;
        if (!try_parse_number(v, w) || !std::isfinite(w) || w < 0)
          throw UsageError(where + ": wall_seconds '" + v + "' is not a number >= 0");
        tr.wall_seconds = w;
      }
      continue;
    }
    if (trim(line).empty()) continue;
    if (!have_header) {
      header = read_header(where, line, info, tr);
      have_header = true;
      continue;
    }
    const Cells cells = split(line);
    if (cells.text.size() != header.coordinate_of_cell.size())
      throw UsageError(where + ": " + std::to_string(cells.text.size()) + " cells, the header has " +
                       std::to_string(header.coordinate_of_cell.size()));
    double t = 0;
    for (size_t k = 0; k < cells.text.size(); ++k) {
      const int c = header.coordinate_of_cell[k];
      if (c == -2) continue;
      double v = 0;
      const std::string at = where + ":" + std::to_string(cells.column[k]) + ": ";
      if (!try_parse_number(cells.text[k], v))
        throw UsageError(at + "'" + cells.text[k] + "' is not a number");
      if (!std::isfinite(v)) throw UsageError(at + "'" + cells.text[k] + "' is not finite");
      if (c == -1) {
        if (!tr.t.empty() && !(v > tr.t.back()))
          throw UsageError(at + "t = " + cells.text[k] + " does not increase (the row before has t = " +
                           format_exact(tr.t.back()) + ")");
        t = v;
      } else {
        row[c] = v;
      }
    }
    tr.t.push_back(t);
    tr.values.insert(tr.values.end(), row.begin(), row.end());
  }
  if (!have_header) throw UsageError(path + ": empty (no header line)");
  const size_t need = tr.differenced.empty() ? 2 : 3;
  if (tr.rows() < need)
    throw UsageError(path + ": " + std::to_string(tr.rows()) + " rows; scoring needs at least " +
                     std::to_string(need) + (tr.differenced.empty() ? "" : " (velocities are differenced)"));
  // The differenced velocities, from their position columns.
  std::vector<double> x(tr.rows()), dx;
  for (size_t c = 0; c < nc; ++c) {
    const int p = header.position_of_coordinate[c];
    if (p < 0) continue;
    for (size_t r = 0; r < tr.rows(); ++r) x[r] = tr.values[r * nc + p];
    difference(tr.t, x, dx);
    for (size_t r = 0; r < tr.rows(); ++r) tr.values[r * nc + c] = dx[r];
  }
  return tr;
}

namespace {

// The canonical state at `t` between rows: the cubic through the four
// nearest rows (fewer if the trajectory has fewer).
std::vector<double> interpolate(const Trajectory& tr, size_t nc, double t) {
  const size_t n = tr.rows();
  const size_t upper = size_t(std::upper_bound(tr.t.begin(), tr.t.end(), t) - tr.t.begin());
  const size_t width = std::min<size_t>(4, n);
  size_t first = upper >= 2 ? upper - 2 : 0;
  first = std::min(first, n - width);
  std::vector<double> out(nc, 0);
  for (size_t j = first; j < first + width; ++j) {
    double w = 1;
    for (size_t k = first; k < first + width; ++k)
      if (k != j) w *= (t - tr.t[k]) / (tr.t[j] - tr.t[k]);
    for (size_t c = 0; c < nc; ++c) out[c] += w * tr.values[j * nc + c];
  }
  return out;
}

void check_settings(const ScoreConfig& cfg) {
  if (!(cfg.blowup > 0)) throw UsageError("--blowup: must be > 0");
  if (!(cfg.recovery_threshold > 0)) throw UsageError("--recovery-threshold: must be > 0");
  if (!std::isfinite(cfg.drift_fit_from) || cfg.drift_fit_from < 0)
    throw UsageError("--drift-fit-from: must be a finite number >= 0 (0: no fit)");
  if (cfg.sample_every < 0 || !std::isfinite(cfg.sample_every))
    throw UsageError("--sample-every: must be a finite number >= 0");
  if (std::isnan(cfg.ref_time) || std::isinf(cfg.ref_time)) throw UsageError("--ref-time: must be a finite number");
  if (!std::isnan(cfg.wall_seconds) && !(cfg.wall_seconds >= 0 && std::isfinite(cfg.wall_seconds)))
    throw UsageError("--wall-seconds: must be a finite number >= 0");
  if (cfg.label.empty()) throw UsageError("--label: must not be empty");
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ";") + n;
  return s.empty() ? "none" : s;
}

}  // namespace

RunResult score_trajectory(const Problem& registered, const ScoreConfig& cfg, const std::string& path,
                           const std::string& out_dir) {
  // ---- validate everything, the whole file included, before writing ----
  check_settings(cfg);
  std::string problem_params;
  const std::unique_ptr<Problem> variant = problem_variant(registered, cfg.problem_params, &problem_params);
  const Problem& problem = variant ? *variant : registered;
  const ProblemInfo& info = problem.info();
  std::unique_ptr<Formulation> form = problem.make_observer();
  if (!form)
    throw UsageError("problem '" + info.name + "': no formulation has the canonical coordinates as its state, "
                     "so a trajectory of them cannot be scored");
  if (!cfg.formulation.empty() && cfg.formulation != form->formulation_name())
    throw UsageError("--formulation " + cfg.formulation + ": problem '" + info.name +
                     "' scores a trajectory of its canonical coordinates in the '" + form->formulation_name() +
                     "' formulation (the one whose state they are)");
  const Trajectory tr = read_trajectory(path, info);
  const size_t nc = info.coordinates.size();

  RunResult result;
  result.problem = cfg.problem;
  result.problem_params = problem_params;
  result.formulation = form->formulation_name();
  result.method = cfg.label;
  result.integrator = "external";
  result.t_end = tr.t.back();
  result.recovery_threshold = cfg.recovery_threshold;
  double ref_time = cfg.ref_time < 0 ? info.reference_time : cfg.ref_time;
  if (ref_time > tr.t.back() || ref_time < tr.t.front() || ref_time <= 0) ref_time = 0;
  if (ref_time > 0) {
    result.ref_state.assign(nc, 0);
    if (!problem.reference(ref_time, result.ref_state.data())) {
      ref_time = 0;
      result.ref_state.clear();
    }
  }
  if (ref_time > 0) result.ref_time = ref_time;

  RunOutputs outputs(out_dir, cfg.write_series);

  // ---- observe every row, as `cstab run` observes every step ----
  const double span = tr.t.back() - tr.t.front();
  const double sample_every = cfg.sample_every > 0 ? cfg.sample_every : (span > 0 ? span / 1000 : 1);
  Recorder recorder(problem, *form, result, outputs.series(), sample_every, cfg.drift_fit_from, tr.t.back());
  std::string ref_interpolation;
  bool alive = true;
  for (size_t r = 0; r < tr.rows() && alive; ++r) {
    const double t = tr.t[r];
    const double* y = tr.values.data() + r * nc;
    alive = recorder.observe(t, y, r == 0 || r + 1 == tr.rows(), cfg.blowup);
    if (alive && t == ref_time) {
      result.state_at_ref = recorder.canonical();
      ref_interpolation = "row";
    } else if (alive && ref_time > t && r + 1 < tr.rows() && ref_time < tr.t[r + 1]) {
      result.state_at_ref = interpolate(tr, nc, ref_time);
      ref_interpolation = "cubic";
    }
    if (alive && r + 1 == tr.rows()) result.final_state = recorder.canonical();
  }
  if (!result.state_at_ref.empty() && ref_time > 0) {
    double err = 0;
    for (size_t i = 0; i < nc; ++i)
      if (!std::isnan(result.ref_state[i])) err = std::max(err, std::abs(result.state_at_ref[i] - result.ref_state[i]));
    result.ref_error = err;
    result.ref_scd = significant_digits(result.state_at_ref, result.ref_state);
  }
  if (result.status != "ok") result.recovery_time = std::numeric_limits<double>::quiet_NaN();
  recorder.fit_drift_growth();
  result.steps = long(tr.rows()) - 1;
  result.rejected_steps = -1;
  result.rhs_evals = -1;
  result.wall_seconds = std::isnan(cfg.wall_seconds) ? tr.wall_seconds : cfg.wall_seconds;
  std::vector<double> initial(nc), y0(nc);
  form->initial_state(y0.data());
  form->to_canonical(0.0, y0.data(), initial.data());
  double deviation = 0;
  for (size_t i = 0; i < nc; ++i) deviation = std::max(deviation, std::abs(tr.values[i] - initial[i]));
  result.extra = {{"rows", std::to_string(tr.rows())},
                  {"differenced", joined(tr.differenced)},
                  {"ref_interpolation", ref_interpolation},
                  {"initial_state_deviation", format_exact(deviation)}};

  // ---- write ----
  outputs.commit(result);
  return result;
}

}  // namespace cstab

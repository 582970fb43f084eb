#include "gate/gate.hpp"

// fast-cpp-csv-parser reads on a background thread by default; the files are
// small and a thread complicates sanitizer and fuzzing runs.
#define CSV_IO_NO_THREAD
// (its error types copy names with strncpy into fixed buffers, by design;
// GCC's warning only: clang has no such group and would warn on the pragma)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstringop-truncation"
#endif
#include <libfccp/csv.h>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "core/format.hpp"
#include "io/csv.hpp"
#include "io/number.hpp"
#include "matrix/matrix.hpp"
#include "matrix/results.hpp"

namespace cstab {

namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Measured values below this count as this when a bound is derived from them:
// round-off differs between machines and compilers.
constexpr double kValueFloor = 1e-15;

// The known columns, in --init order. Keep in sync with the CSVReader below.
const std::vector<std::string> kColumns = {
    "name",          "sweep",          "problem",          "method",           "formulation",
    "integrator",    "params",         "setting",          "t_end",            "status",
    "max_residual",  "max_final_residual", "max_energy_drift", "max_integral_drift", "max_ref_error",
    "min_ref_scd",   "max_recovery_time", "baseline",       "max_time_ratio",   "note"};
constexpr unsigned kColumnCount = 20;

const std::vector<std::string> kRequired = {"problem", "method", "integrator", "setting"};

using Reader = io::CSVReader<kColumnCount, io::trim_chars<' ', '\t'>, io::double_quote_escape<',', '"'>,
                             io::throw_on_overflow, io::single_and_empty_line_comment<'#'>>;

std::string where(const std::string& file, int line, int column) {
  std::string s = file + ":" + std::to_string(line);
  if (column > 0) s += ":" + std::to_string(column);
  return s;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string cur;
  for (char c : text) {
    if (c == '\n') {
      if (!cur.empty() && cur.back() == '\r') cur.pop_back();
      lines.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) lines.push_back(cur);
  return lines;
}

bool is_comment_line(const std::string& line) {
  if (!line.empty() && line[0] == '#') return true;
  return line.find_first_not_of(" \t") == std::string::npos;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// Header cells (names never need quoting; surrounding quotes are dropped).
std::vector<std::string> split_header(const std::string& line) {
  std::vector<std::string> cells;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      cells.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  cells.push_back(cur);
  for (auto& c : cells) {
    c = trim(c);
    if (c.size() >= 2 && c.front() == '"' && c.back() == '"') c = c.substr(1, c.size() - 2);
  }
  return cells;
}

std::string known_columns_text() {
  std::string s;
  for (const auto& c : kColumns) s += (s.empty() ? "" : ", ") + c;
  return s;
}

// Strict: the whole cell must be a finite number.
double number_or_throw(const std::string& text, const std::string& at, const std::string& column) {
  double v = 0;
  if (!try_parse_number(text, v)) throw UsageError(at + ": " + column + ": '" + text + "' is not a number");
  if (!std::isfinite(v)) throw UsageError(at + ": " + column + ": '" + text + "' is not finite (leave the cell empty for no bound)");
  return v;
}

std::string fmt(double v) { return format_3g(v); }

// A bound written with 3 significant digits, rounded outwards so that the
// value it was derived from still passes (upper: >= v, lower: <= v).
std::string fmt_bound(double v, bool lower) {
  double f = 1;
  for (int i = 0; i < 50; ++i, f *= lower ? 1 - 1e-3 : 1 + 1e-3) {
    const std::string s = fmt(v * f);
    const double p = parse_number(s);
    if (lower ? p <= v : p >= v) return s;
  }
  return format_exact(v);
}

// ---- the measured side: a case of the results folder (matrix/results.hpp) ----

bool matches(const ThresholdRow& row, const CaseEntry& e) {
  if (e.problem != row.problem || e.method != row.method || e.integrator != row.integrator ||
      e.formulation != row.formulation || !same_key_values(e.params, row.params) ||
      !same_key_values(e.setting, row.setting))
    return false;
  if (!std::isnan(row.t_end) && e.t_end != row.t_end) return false;
  return row.sweep.empty() || e.sweep == row.sweep;
}

struct Match {
  const CaseEntry* entry = nullptr;
  std::string problem;  // why no single case: empty if found
};

Match find_case(const ThresholdRow& row, const std::vector<CaseEntry>& entries) {
  std::vector<const CaseEntry*> found;
  for (const auto& e : entries)
    if (matches(row, e)) found.push_back(&e);
  Match m;
  if (found.size() == 1) {
    m.entry = found[0];
    return m;
  }
  if (found.size() > 1) {
    m.problem = std::to_string(found.size()) + " cases match (t_end";
    for (const auto* e : found) m.problem += " " + format_short(e->t_end);
    m.problem += "; sweep";
    for (const auto* e : found) m.problem += " " + e->sweep;
    m.problem += "): give t_end or sweep";
    return m;
  }
  m.problem = "no such case in the results folder";
  std::set<std::string> near;
  for (const auto& e : entries)
    if (e.problem == row.problem && e.method == row.method && e.integrator == row.integrator)
      near.insert(e.setting + (e.params.empty() ? "" : " [" + e.params + "]") +
                  (e.formulation.empty() ? "" : " (" + e.formulation + ")"));
  if (!near.empty()) {
    m.problem += "; it has " + row.problem + " " + row.method + " " + row.integrator + " at";
    size_t shown = 0;
    for (const auto& s : near) {
      if (++shown > 6) {
        m.problem += " ...";
        break;
      }
      m.problem += " " + s;
    }
  }
  return m;
}

// One bound of a row: which measured value it reads, and its sense.
struct BoundSpec {
  const char* column;
  double ThresholdRow::*bound;
  double CaseResult::*value;  // nullptr: the time ratio
  bool lower;                 // true: value must be >= bound
};

const BoundSpec kBounds[] = {
    {"max_residual", &ThresholdRow::max_residual, &CaseResult::max_residual, false},
    {"max_final_residual", &ThresholdRow::max_final_residual, &CaseResult::final_residual, false},
    {"max_energy_drift", &ThresholdRow::max_energy_drift, &CaseResult::max_energy_drift, false},
    {"max_integral_drift", &ThresholdRow::max_integral_drift, &CaseResult::max_integral_drift, false},
    {"max_ref_error", &ThresholdRow::max_ref_error, &CaseResult::ref_error, false},
    {"min_ref_scd", &ThresholdRow::min_ref_scd, &CaseResult::ref_scd, true},
    {"max_recovery_time", &ThresholdRow::max_recovery_time, &CaseResult::recovery_time, false},
    {"max_time_ratio", &ThresholdRow::max_time_ratio, nullptr, false},
};

std::string margin_text(double value, double threshold, bool lower) {
  if (lower) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%+.2f digits", value - threshold);
    return buf;
  }
  if (value <= 0) return "x inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "x%.3g", threshold / value);
  return buf;
}

int column_index(const ThresholdsFile& file, const std::string& name) {
  for (size_t i = 0; i < file.columns.size(); ++i)
    if (file.columns[i] == name) return int(i);
  return -1;
}

std::string cell(const ThresholdRow& row, int index) {
  return index >= 0 && size_t(index) < row.fields.size() ? row.fields[index] : std::string();
}

}  // namespace

const std::vector<std::string>& threshold_columns() { return kColumns; }

std::string ThresholdRow::label() const {
  std::string s = problem + " " + method + " " + integrator + " " + setting;
  if (!formulation.empty()) s += " (" + formulation + ")";
  if (!sweep.empty()) s += " sweep=" + sweep;
  if (!params.empty()) s += " [" + params + "]";
  if (!std::isnan(t_end)) s += " t_end=" + format_short(t_end);
  return s;
}

namespace {

// The header line: its column names and 0-based positions, checked here so errors name columns.
std::map<std::string, int> parse_header(ThresholdsFile& file, const std::string& text) {
  const std::string& file_name = file.name;
  if (text.find('\0') != std::string::npos) {
    int line = 1;
    for (char c : text.substr(0, text.find('\0'))) line += c == '\n';
    throw UsageError(where(file_name, line, 0) + ": NUL byte: not a text file");
  }
  int header_line = 0;
  for (size_t i = 0; i < file.lines.size(); ++i)
    if (!is_comment_line(file.lines[i])) {
      header_line = int(i) + 1;
      break;
    }
  if (header_line == 0) throw UsageError(file_name + ": no header line (expected columns: " + known_columns_text() + ")");
  file.columns = split_header(file.lines[header_line - 1]);
  std::map<std::string, int> position;  // column name -> 0-based position
  for (size_t i = 0; i < file.columns.size(); ++i) {
    const std::string& c = file.columns[i];
    const std::string at = where(file_name, header_line, int(i) + 1);
    if (c.empty()) throw UsageError(at + ": empty column name");
    if (std::find(kColumns.begin(), kColumns.end(), c) == kColumns.end())
      throw UsageError(at + ": unknown column '" + c + "' (known: " + known_columns_text() + ")");
    if (position.count(c)) throw UsageError(at + ": column '" + c + "' appears twice");
    position[c] = int(i);
  }
  for (const auto& c : kRequired)
    if (!position.count(c)) throw UsageError(where(file_name, header_line, 0) + ": missing required column '" + c + "'");
  return position;
}

// The key a row names a case by, for duplicate detection: settings and parameters in canonical form.
std::string case_key(const ThresholdRow& row) {
  return row.problem + " " + row.method + " " + row.integrator + " " + canonical_key_values(row.setting) + " (" +
         row.formulation + ") " + row.sweep + " [" + canonical_key_values(row.params) + "] " +
         (std::isnan(row.t_end) ? "" : format_short(row.t_end));
}

// One data row from its cells (by known column; nullptr: not in the file).
ThresholdRow parse_row(const ThresholdsFile& file, std::map<std::string, int>& position, int line,
                       char* const* cells) {
  ThresholdRow row;
  row.line = line;
  row.fields.assign(file.columns.size(), "");
  std::map<std::string, std::string> value;
  for (unsigned k = 0; k < kColumnCount; ++k) {
    if (!cells[k]) continue;
    value[kColumns[k]] = cells[k];
    row.fields[position[kColumns[k]]] = cells[k];
  }
  auto at = [&](const std::string& column) { return where(file.name, row.line, position[column] + 1); };
  auto text_of = [&](const std::string& column) {
    auto it = value.find(column);
    return it == value.end() ? std::string() : it->second;
  };
  for (const auto& c : kRequired)
    if (text_of(c).empty()) throw UsageError(at(c) + ": " + c + ": required, empty");
  row.name = text_of("name");
  row.sweep = text_of("sweep");
  row.problem = text_of("problem");
  row.method = text_of("method");
  row.formulation = text_of("formulation");
  row.integrator = text_of("integrator");
  row.params = text_of("params");
  row.setting = text_of("setting");
  row.baseline = text_of("baseline");
  if (!text_of("t_end").empty()) {
    row.t_end = number_or_throw(text_of("t_end"), at("t_end"), "t_end");
    if (!(row.t_end > 0)) throw UsageError(at("t_end") + ": t_end: must be > 0");
  }
  if (!text_of("status").empty()) {
    const auto status = parse_status(text_of("status"));
    if (!status || !is_gateable(*status))
      throw UsageError(at("status") + ": status: '" + text_of("status") + "' is not one of ok, diverged, failed");
    row.status = *status;
  }
  for (const auto& b : kBounds) {
    const std::string s = text_of(b.column);
    if (s.empty()) continue;
    const double v = number_or_throw(s, at(b.column), b.column);
    if (v < 0) throw UsageError(at(b.column) + ": " + b.column + ": " + s + " is negative (bounds are >= 0)");
    if (std::string(b.column) == "max_time_ratio" && v == 0)
      throw UsageError(at(b.column) + ": max_time_ratio: must be > 0");
    row.*(b.bound) = v;
  }
  if (!std::isnan(row.max_time_ratio) && row.baseline.empty())
    throw UsageError(at("max_time_ratio") + ": max_time_ratio needs a baseline (the name of another row)");
  if (std::isnan(row.max_time_ratio) && !row.baseline.empty())
    throw UsageError(at("baseline") + ": baseline given without max_time_ratio");
  return row;
}

// The rows, tokenized by fast-cpp-csv-parser (quoting, trimming, comments); no duplicate case or name.
void parse_rows(ThresholdsFile& file, const std::string& text, std::map<std::string, int>& position,
                std::map<std::string, int>& name_line) {
  const std::string& file_name = file.name;
  Reader reader(file_name, text.data(), text.data() + text.size());
  std::map<std::string, int> key_line;
  try {
    reader.read_header(io::ignore_missing_column, "name", "sweep", "problem", "method", "formulation", "integrator",
                       "params", "setting", "t_end", "status", "max_residual", "max_final_residual",
                       "max_energy_drift", "max_integral_drift", "max_ref_error", "min_ref_scd",
                       "max_recovery_time", "baseline", "max_time_ratio", "note");
    char* cells[kColumnCount];
    while (true) {
      std::fill(cells, cells + kColumnCount, nullptr);
      if (!reader.read_row(cells[0], cells[1], cells[2], cells[3], cells[4], cells[5], cells[6], cells[7], cells[8],
                           cells[9], cells[10], cells[11], cells[12], cells[13], cells[14], cells[15], cells[16],
                           cells[17], cells[18], cells[19]))
        break;
      ThresholdRow row = parse_row(file, position, int(reader.get_file_line()), cells);
      const std::string key = case_key(row);
      if (key_line.count(key))
        throw UsageError(where(file_name, row.line, 0) + ": duplicate case " + row.label() + " (first at line " +
                         std::to_string(key_line[key]) + ")");
      key_line[key] = row.line;
      if (!row.name.empty()) {
        if (name_line.count(row.name))
          throw UsageError(where(file_name, row.line, position["name"] + 1) + ": duplicate name '" + row.name +
                           "' (first at line " + std::to_string(name_line[row.name]) + ")");
        name_line[row.name] = row.line;
      }
      file.rows.push_back(std::move(row));
    }
  } catch (const io::error::too_many_columns& e) {
    throw UsageError(where(file_name, e.file_line, 0) + ": more cells than the header's " +
                     std::to_string(file.columns.size()) + " columns");
  } catch (const io::error::too_few_columns& e) {
    throw UsageError(where(file_name, e.file_line, 0) + ": fewer cells than the header's " +
                     std::to_string(file.columns.size()) + " columns");
  } catch (const io::error::escaped_string_not_closed& e) {
    throw UsageError(where(file_name, e.file_line, 0) + ": unterminated quoted cell");
  } catch (const io::error::base& e) {
    throw UsageError(file_name + ": " + e.what());
  }
}

// Every baseline names another row.
void check_baselines(const ThresholdsFile& file, std::map<std::string, int>& position,
                     const std::map<std::string, int>& name_line) {
  for (const auto& row : file.rows) {
    if (row.baseline.empty()) continue;
    if (!name_line.count(row.baseline))
      throw UsageError(where(file.name, row.line, position["baseline"] + 1) + ": baseline '" + row.baseline +
                       "' is not the name of any row");
    if (row.baseline == row.name)
      throw UsageError(where(file.name, row.line, position["baseline"] + 1) + ": a row cannot be its own baseline");
  }
}

}  // namespace

ThresholdsFile parse_thresholds(const std::string& text, const std::string& file_name) {
  ThresholdsFile file;
  file.name = file_name;
  file.lines = split_lines(text);
  // The header: names and positions.
  std::map<std::string, int> position = parse_header(file, text);
  // The rows.
  std::map<std::string, int> name_line;
  parse_rows(file, text, position, name_line);
  // Cross-row checks.
  check_baselines(file, position, name_line);
  return file;
}

ThresholdsFile read_thresholds_file(const std::string& path) {
  std::string text;
  try {
    text = read_text_file(path);
  } catch (const std::exception& e) {
    throw UsageError("--thresholds " + path + ": cannot read: " + e.what());
  }
  return parse_thresholds(text, path);
}

namespace {

std::string row_text(const ThresholdRow& row) { return csv_line(row.fields); }

}  // namespace

std::string thresholds_text(const ThresholdsFile& file) {
  std::map<int, const ThresholdRow*> by_line;
  for (const auto& r : file.rows) by_line[r.line] = &r;
  std::string out;
  std::set<int> written;
  for (size_t i = 0; i < file.lines.size(); ++i) {
    const int line = int(i) + 1;
    auto it = by_line.find(line);
    if (it == by_line.end()) {
      out += file.lines[i] + "\n";
      continue;
    }
    out += row_text(*it->second);
    written.insert(line);
  }
  for (const auto& r : file.rows)  // rows added after parsing (line beyond the text)
    if (!written.count(r.line)) out += row_text(r);
  return out;
}

GateOutcome evaluate_gate(const ThresholdsFile& file, const std::string& dir) {
  const std::vector<CaseEntry> entries = read_results_manifest(dir);
  GateOutcome out;
  std::map<std::string, CaseResult> by_name;  // row name -> its case (for baselines)
  std::vector<CaseResult> results(file.rows.size());
  std::vector<std::string> problems(file.rows.size());
  std::set<const CaseEntry*> named;
  for (size_t i = 0; i < file.rows.size(); ++i) {
    const Match m = find_case(file.rows[i], entries);
    if (m.entry) named.insert(m.entry);
    if (m.entry) results[i] = load_case_result(dir, *m.entry);
    problems[i] = m.entry ? (results[i].complete ? "" : "case " + m.entry->id + " has no complete result")
                          : m.problem;
    if (!file.rows[i].name.empty()) by_name[file.rows[i].name] = results[i];
  }
  for (const auto& e : entries)
    if (!named.count(&e) && is_gateable(load_case_result(dir, e).status)) {  // n/a ones aside
      ++out.unchecked_cases;
      out.unchecked.push_back(e.label() + " (" + e.id + ")");
    }
  for (size_t i = 0; i < file.rows.size(); ++i) {
    const ThresholdRow& row = file.rows[i];
    const CaseResult& r = results[i];
    auto add = [&](GateCheck c) {
      c.case_label = row.label();
      c.line = row.line;
      if (!c.pass) ++out.failed;
      out.checks.push_back(std::move(c));
    };
    if (!problems[i].empty()) {
      GateCheck c;
      c.check = "case";
      c.value = "missing";
      c.threshold = "present";
      c.note = problems[i];
      add(c);
      continue;
    }
    {
      GateCheck c;
      c.check = "status";
      c.value = status_name(r.status);
      c.threshold = status_name(row.status);
      c.pass = r.status == row.status;
      if (!c.pass && !r.reason.empty()) c.note = r.reason;
      add(c);
    }
    for (const auto& b : kBounds) {
      const double bound = row.*(b.bound);
      if (std::isnan(bound)) continue;
      GateCheck c;
      c.check = b.column;
      c.threshold = (b.lower ? ">= " : "<= ") + fmt(bound);
      double value = kNaN;
      if (b.value) {
        value = r.*(b.value);
        if (std::isnan(value)) c.note = "the case has no value for it";
      } else {
        const CaseResult& base = by_name[row.baseline];
        if (!base.complete || std::isnan(base.wall_median) || std::isnan(r.wall_median))
          c.note = "no successful timing of the case or of baseline '" + row.baseline + "'";
        else if (base.wall_median <= 0)
          c.note = "baseline '" + row.baseline + "' took no measurable time";
        else
          value = r.wall_median / base.wall_median;
      }
      c.value = std::isnan(value) ? "n/a" : fmt(value);
      c.value_number = value;
      c.pass = !std::isnan(value) && (b.lower ? value >= bound : value <= bound);
      if (!std::isnan(value)) c.margin = margin_text(value, bound, b.lower);
      add(c);
    }
  }
  return out;
}

std::string format_gate_table(const GateOutcome& outcome) {
  const std::vector<std::string> head = {"line", "case", "check", "value", "threshold", "margin", "result"};
  std::vector<std::vector<std::string>> rows;
  for (const auto& c : outcome.checks)
    rows.push_back({std::to_string(c.line), c.case_label, c.check, c.value, c.threshold, c.margin,
                    c.pass ? "pass" : "FAIL"});
  std::vector<size_t> width(head.size());
  for (size_t k = 0; k < head.size(); ++k) width[k] = head[k].size();
  for (const auto& r : rows)
    for (size_t k = 0; k < r.size(); ++k) width[k] = std::max(width[k], r[k].size());
  std::ostringstream s;
  auto line = [&](const std::vector<std::string>& r) {
    std::string l;
    for (size_t k = 0; k < r.size(); ++k) {
      l += r[k];
      if (k + 1 < r.size()) l += std::string(width[k] - r[k].size() + 2, ' ');
    }
    s << l << "\n";
  };
  line(head);
  for (size_t i = 0; i < rows.size(); ++i) {
    line(rows[i]);
    if (!outcome.checks[i].note.empty()) s << "      " << outcome.checks[i].note << "\n";
  }
  s << "gate: " << outcome.checks.size() << " checks, " << outcome.failed << " failed";
  if (outcome.unchecked_cases)
    s << " (" << outcome.unchecked_cases << " cases of the folder have no thresholds: not checked)";
  s << "\n";
  return s.str();
}

std::string gate_csv(const GateOutcome& outcome) {
  std::string s = "line,case,check,value,threshold,margin,result,note\n";
  for (const auto& c : outcome.checks)
    s += csv_line({std::to_string(c.line), c.case_label, c.check,
                   std::isnan(c.value_number) ? c.value : format_exact(c.value_number), c.threshold, c.margin,
                   c.pass ? "pass" : "fail", c.note});
  return s;
}

namespace {

// The bound a measured value implies (GateFactors).
double derived_bound(const BoundSpec& b, double value, const GateFactors& f) {
  if (b.lower) return std::max(0.0, value - std::log10(f.value));
  if (!b.value) return value * f.time_ratio;
  if (b.bound == &ThresholdRow::max_recovery_time) return value * f.recovery;
  return std::max(value, kValueFloor) * f.value;
}

// The text of a derived bound; UsageError if it is not a finite number the
// parser reads back (a factor so large the bound overflows).
std::string bound_text(const BoundSpec& b, double value, const GateFactors& f, const std::string& label) {
  const double bound = derived_bound(b, value, f);
  const std::string text = fmt_bound(bound, b.lower);
  double back = 0;
  if (!std::isfinite(bound) || !try_parse_number(text, back) || !std::isfinite(back))
    throw UsageError(label + ": " + b.column + " = " + fmt(value) + " x factor is not a finite number (" + text +
                     "); use a smaller --factor/--time-factor/--recovery-factor (nothing written)");
  return text;
}

void check_factors(const GateFactors& f) {
  auto check = [](double v, const char* flag) {
    if (!(v >= 1) || !std::isfinite(v)) throw UsageError(std::string(flag) + ": must be a finite number >= 1");
  };
  check(f.value, "--factor");
  check(f.time_ratio, "--time-factor");
  check(f.recovery, "--recovery-factor");
}

void set_cell(ThresholdsFile& file, ThresholdRow& row, const std::string& column, const std::string& text) {
  const int k = column_index(file, column);
  if (k >= 0) row.fields[k] = text;
}

}  // namespace

std::vector<ThresholdChange> update_thresholds(ThresholdsFile& file, const std::string& dir,
                                               const GateFactors& factors, std::vector<std::string>& notes) {
  check_factors(factors);
  const std::vector<CaseEntry> entries = read_results_manifest(dir);
  std::vector<ThresholdChange> changes;
  std::vector<CaseResult> results(file.rows.size());
  std::map<std::string, size_t> by_name;
  for (size_t i = 0; i < file.rows.size(); ++i) {
    const Match m = find_case(file.rows[i], entries);
    if (m.entry) results[i] = load_case_result(dir, *m.entry);
    if (!file.rows[i].name.empty()) by_name[file.rows[i].name] = i;
    if (!m.entry || !results[i].complete)
      notes.push_back("line " + std::to_string(file.rows[i].line) + ": " + file.rows[i].label() +
                      ": kept unchanged (" + (m.entry ? "no complete result" : m.problem) + ")");
  }
  for (size_t i = 0; i < file.rows.size(); ++i) {
    ThresholdRow& row = file.rows[i];
    const CaseResult& r = results[i];
    if (!r.complete) continue;
    auto change = [&](const std::string& column, const std::string& text) {
      const std::string old = cell(row, column_index(file, column));
      if (old == text) return;
      changes.push_back({row.label(), column, old, text});
      set_cell(file, row, column, text);
    };
    if (column_index(file, "status") >= 0 && !cell(row, column_index(file, "status")).empty()) {
      change("status", status_name(r.status));
      row.status = r.status;
    }
    for (const auto& b : kBounds) {
      if (std::isnan(row.*(b.bound))) continue;
      double value = kNaN;
      if (b.value) {
        value = r.*(b.value);
      } else {
        const CaseResult& base = results[by_name[row.baseline]];
        if (base.complete && base.wall_median > 0) value = r.wall_median / base.wall_median;
      }
      if (std::isnan(value)) {
        notes.push_back("line " + std::to_string(row.line) + ": " + row.label() + ": " + b.column +
                        " kept (no measured value)");
        continue;
      }
      const std::string text = bound_text(b, value, factors, row.label());
      change(b.column, text);
      row.*(b.bound) = parse_number(text);
    }
  }
  return changes;
}

namespace {

// Rows for the completed, gateable cases of `entries` that `skip` does not
// hold, by the rule of --init, appended to `file`.
std::vector<std::string> append_rows(ThresholdsFile& file, const std::string& dir,
                                     const std::vector<CaseEntry>& entries, const std::set<const CaseEntry*>& skip,
                                     const GateFactors& factors) {
  std::vector<std::string> added;
  // Several cases may share a key but for t_end or their sweep; give t_end
  // (and the sweep) only then.
  std::map<std::string, int> key_count, key_t_count;
  auto key_of = [](const CaseEntry& e) {
    return e.problem_label() + "|" + e.method + "|" + e.formulation + "|" + e.integrator + "|" + e.params + "|" +
           e.setting;
  };
  auto key_t_of = [&](const CaseEntry& e) { return key_of(e) + "|" + format_exact(e.t_end); };
  for (const auto& e : entries) {
    ++key_count[key_of(e)];
    ++key_t_count[key_t_of(e)];
  }
  int last_line = int(file.lines.size());
  for (const auto& r : file.rows) last_line = std::max(last_line, r.line);
  for (const auto& e : entries) {
    if (skip.count(&e)) continue;
    const CaseResult r = load_case_result(dir, e);
    if (!r.complete || !is_gateable(r.status)) continue;  // n/a (invalid), timeout, crashed: not gated
    ThresholdRow row;
    row.line = ++last_line;
    file.lines.push_back("");  // placeholder; thresholds_text writes the row here
    row.fields.assign(file.columns.size(), "");
    row.problem = e.problem;
    row.method = e.method;
    row.formulation = e.formulation;
    row.integrator = e.integrator;
    row.params = e.params;
    row.setting = e.setting;
    row.status = r.status;
    if (key_count[key_of(e)] > 1) row.t_end = e.t_end;
    if (key_t_count[key_t_of(e)] > 1) row.sweep = e.sweep;
    set_cell(file, row, "sweep", row.sweep);
    set_cell(file, row, "problem", e.problem);
    set_cell(file, row, "method", e.method);
    set_cell(file, row, "formulation", e.formulation);
    set_cell(file, row, "integrator", e.integrator);
    set_cell(file, row, "params", e.params);
    set_cell(file, row, "setting", e.setting);
    if (!std::isnan(row.t_end)) set_cell(file, row, "t_end", format_short(e.t_end));
    set_cell(file, row, "status", status_name(r.status));
    if (r.status == Status::kOk)
      for (const auto& b : kBounds) {
        if (!b.value) continue;
        const double value = r.*(b.value);
        if (std::isnan(value)) continue;
        if (b.bound == &ThresholdRow::max_recovery_time && e.setting.find("perturb=") == std::string::npos)
          continue;  // a consistent start has nothing to recover from
        if (b.lower && value < 1) continue;  // not one correct digit: max_ref_error says it better
        if (column_index(file, b.column) < 0) continue;  // a file without that column
        const std::string text = bound_text(b, value, factors, row.label());
        set_cell(file, row, b.column, text);
        row.*(b.bound) = parse_number(text);
      }
    added.push_back(row.label());
    file.rows.push_back(std::move(row));
  }
  return added;
}

}  // namespace

ThresholdsFile initial_thresholds(const std::string& dir, const GateFactors& factors, const std::string& file_name) {
  check_factors(factors);
  const std::vector<CaseEntry> entries = read_results_manifest(dir);
  ThresholdsFile file;
  file.name = file_name;
  file.columns = kColumns;
  file.lines.push_back("# cstab gate thresholds, written by `cstab gate --init` from " + dir +
                       " with safety factors " + format_short(factors.value) + " (values), " +
                       format_short(factors.recovery) + " (recovery times) (docs/gate.md)");
  std::string header;
  for (const auto& c : kColumns) header += (header.empty() ? "" : ",") + c;
  file.lines.push_back(header);
  append_rows(file, dir, entries, {}, factors);
  return file;
}

std::vector<std::string> add_missing_thresholds(ThresholdsFile& file, const std::string& dir,
                                                const GateFactors& factors) {
  check_factors(factors);
  for (const char* needed : {"problem", "method", "integrator", "setting"})
    if (column_index(file, needed) < 0) throw UsageError(file.name + ": no column '" + needed + "'");
  const std::vector<CaseEntry> entries = read_results_manifest(dir);
  std::set<const CaseEntry*> named;
  for (const auto& row : file.rows) {
    const Match m = find_case(row, entries);
    if (m.entry) named.insert(m.entry);
  }
  return append_rows(file, dir, entries, named, factors);
}

}  // namespace cstab

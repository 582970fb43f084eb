#include "matrix/results.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/format.hpp"
#include "io/gzip.hpp"
#include "io/hash.hpp"
#include "io/number.hpp"

namespace cstab {

namespace fs = std::filesystem;

namespace {

struct StatusName {
  Status status;
  const char* name;
};
constexpr StatusName kStatusNames[] = {
    {Status::kOk, "ok"},           {Status::kDiverged, "diverged"}, {Status::kFailed, "failed"},
    {Status::kTimeout, "timeout"}, {Status::kCrashed, "crashed"},   {Status::kInvalid, "invalid"},
    {Status::kNotRun, "not run"},
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// "max_<name>_drift" (not energy): the name, else "".
std::string integral_drift_name(const std::string& column) {
  if (column.size() > 10 && column.rfind("max_", 0) == 0 && ends_with(column, "_drift") &&
      column != "max_energy_drift")
    return column.substr(4, column.size() - 10);
  return "";
}

// "<name>_drift_exponent" (not energy): the name, else "".
std::string exponent_name(const std::string& column) {
  if (column.size() > 15 && ends_with(column, "_drift_exponent") && column != "energy_drift_exponent")
    return column.substr(0, column.size() - 15);
  return "";
}

double nan_max(double a, double b) {
  if (std::isnan(a)) return b;
  if (std::isnan(b)) return a;
  return std::max(a, b);
}

double nan_min(double a, double b) {
  if (std::isnan(a)) return b;
  if (std::isnan(b)) return a;
  return std::min(a, b);
}

long count(const std::string& text) {
  const double v = parse_number(text);
  return std::isfinite(v) ? long(v) : -1;
}

void add_value(std::vector<std::pair<std::string, double>>& list, const std::string& name, double v) {
  for (auto& [n, x] : list)
    if (n == name) {
      x = nan_max(x, v);
      return;
    }
  list.emplace_back(name, v);
}

// The report's drift: energy, else the largest first integral (names in `order`).
void set_drift(CaseResult& c, const std::vector<std::string>& order) {
  c.drift = kNoValue;
  c.drift_name.clear();
  if (c.energy_law) {
    c.drift = c.max_energy_drift;
    c.drift_name = "energy";
    return;
  }
  std::string names;
  for (const auto& name : order)
    for (const auto& [n, v] : c.max_integral_drifts) {
      if (n != name || std::isnan(v)) continue;
      c.drift = nan_max(c.drift, v);
      names += (names.empty() ? "" : ", ") + n;
    }
  if (!names.empty()) c.drift_name = "first integrals (" + names + ")";
}

// Folds one summary.csv row (repeat) into `c`.
void add_repeat(CaseResult& c, const CsvTable& t, size_t i) {
  auto text = [&](const char* col) -> const std::string& { return t.get(i, col); };
  auto num = [&](const char* col) { return parse_number(t.get(i, col)); };
  RepeatResult r;
  r.status = status_from_cell(text("status"));
  r.reason = text("reason");
  r.wall_seconds = num("wall_seconds");
  if (c.repeats.empty() || (c.status == Status::kOk && r.status != Status::kOk)) {
    c.status = r.status;
    c.reason = r.reason;
  }
  if (c.repeats.empty()) {  // configuration and counts: the first repeat
    c.formulation = text("formulation");
    c.step = num("step");
    c.rtol = num("rtol");
    c.atol = num("atol");
    c.t_end = num("t_end");
    c.steps = count(text("steps"));
    c.rejected_steps = count(text("rejected_steps"));
    c.rhs_evals = count(text("rhs_evals"));
    c.energy_law = text("energy_law") == "yes";
    c.ref_time = num("ref_time");
    c.perturb = num("perturb");
    c.recovered = text("recovered") == "yes";
  }
  c.max_residual = nan_max(c.max_residual, num("max_residual"));
  c.final_residual = nan_max(c.final_residual, num("final_residual"));
  c.max_energy_drift = nan_max(c.max_energy_drift, num("max_energy_drift"));
  c.max_condition = nan_max(c.max_condition, num("max_condition"));
  c.ref_error = nan_max(c.ref_error, num("ref_error"));
  c.ref_scd = nan_min(c.ref_scd, num("ref_scd"));
  c.initial_residual = nan_max(c.initial_residual, num("initial_residual"));
  c.recovery_time = nan_max(c.recovery_time, num("recovery_time"));
  c.energy_drift_exponent = nan_max(c.energy_drift_exponent, num("energy_drift_exponent"));
  for (size_t k = 0; k < t.header.size(); ++k) {
    const std::string& col = t.header[k];
    const std::string cell = k < t.rows[i].size() ? t.rows[i][k] : std::string();
    if (const std::string n = integral_drift_name(col); !n.empty()) {
      const double v = parse_number(cell);
      add_value(c.max_integral_drifts, n, v);
      c.max_integral_drift = nan_max(c.max_integral_drift, v);
    } else if (const std::string e = exponent_name(col); !e.empty()) {
      add_value(c.integral_drift_exponents, e, parse_number(cell));
    }
  }
  c.repeats.push_back(std::move(r));
}

}  // namespace

const char* status_name(Status s) {
  for (const auto& [status, name] : kStatusNames)
    if (status == s) return name;
  return "failed";
}

std::optional<Status> parse_status(const std::string& text) {
  for (const auto& [status, name] : kStatusNames)
    if (text == name) return status;
  return std::nullopt;
}

Status status_from_cell(const std::string& text) {
  const auto s = parse_status(text);
  return s && *s != Status::kNotRun ? *s : Status::kFailed;
}

bool is_gateable(Status s) { return s == Status::kOk || s == Status::kDiverged || s == Status::kFailed; }

double median(std::vector<double> v) {
  if (v.empty()) return kNoValue;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string case_record_text(const std::string& head, const std::string& summary) {
  return head + "summary " + std::to_string(summary.size()) + " " + hash_hex(summary) + "\n" + summary;
}

std::optional<CaseRecord> parse_case_record(const std::string& text, std::string& why) {
  size_t at = text.compare(0, 8, "summary ") == 0 ? 0 : text.find("\nsummary ");
  if (at == std::string::npos) {
    why = std::string(kCaseRecordName) + " has no summary line (truncated)";
    return std::nullopt;
  }
  if (at > 0) ++at;
  const size_t end = text.find('\n', at);
  std::istringstream words(text.substr(at, end == std::string::npos ? std::string::npos : end - at));
  std::string tag, hash, extra;
  unsigned long long size = 0;
  if (end == std::string::npos || !(words >> tag >> size >> hash) || (words >> extra)) {
    why = std::string(kCaseRecordName) + ": malformed summary line (truncated or edited)";
    return std::nullopt;
  }
  CaseRecord record{text.substr(0, at), text.substr(end + 1)};
  if (record.summary.size() != size) {
    why = std::string(kCaseRecordName) + ": its summary rows have " + std::to_string(record.summary.size()) +
          " bytes, " + std::to_string(size) + " recorded (truncated or edited)";
    return std::nullopt;
  }
  if (hash_hex(record.summary) != hash) {
    why = std::string(kCaseRecordName) + ": its summary rows differ from the recorded hash (edited)";
    return std::nullopt;
  }
  return record;
}

CaseResult load_case_result(const std::string& dir, const CaseEntry& entry) {
  CaseResult c;
  c.entry = &entry;
  const std::string path = dir + "/cases/" + entry.id + "/" + kCaseRecordName;
  CsvTable t;
  try {
    std::string why;
    const auto record = parse_case_record(read_text_file(path), why);
    if (!record) return c;
    t = parse_csv(record->summary, path);
  } catch (const std::exception&) {
    return c;
  }
  if (t.rows.empty()) return c;
  c.complete = true;
  for (size_t i = 0; i < t.rows.size(); ++i) add_repeat(c, t, i);
  std::vector<double> walls;
  for (const auto& r : c.repeats)
    if (r.status == Status::kOk) walls.push_back(r.wall_seconds);
  c.ok_repeats = int(walls.size());
  if (!walls.empty()) {
    c.wall_median = median(walls);
    c.wall_min = *std::min_element(walls.begin(), walls.end());
    c.wall_max = *std::max_element(walls.begin(), walls.end());
  }
  std::vector<std::string> order;
  for (const auto& [n, v] : c.max_integral_drifts) order.push_back(n);
  set_drift(c, order);
  c.columns = std::move(t.header);
  c.rows = std::move(t.rows);
  return c;
}

ResultsFolder load_results_folder(const std::string& dir) {
  ResultsFolder f;
  f.dir = dir;
  f.entries = read_results_manifest(dir);
  f.cases.reserve(f.entries.size());
  for (const auto& e : f.entries) f.cases.push_back(load_case_result(dir, e));
  for (const auto& c : f.cases)
    for (const auto& col : c.columns) {
      if (const std::string n = integral_drift_name(col); !n.empty()) {
        if (std::find(f.integral_names.begin(), f.integral_names.end(), n) == f.integral_names.end())
          f.integral_names.push_back(n);
      } else if (const std::string e = exponent_name(col); !e.empty()) {
        if (std::find(f.exponent_names.begin(), f.exponent_names.end(), e) == f.exponent_names.end())
          f.exponent_names.push_back(e);
      }
    }
  for (auto& c : f.cases) set_drift(c, f.integral_names);
  return f;
}

std::string case_series_path(const std::string& dir, const CaseEntry& entry) {
  const std::string plain = dir + "/cases/" + entry.id + "/series.csv";
  if (fs::exists(plain + ".gz")) return plain + ".gz";
  return fs::exists(plain) ? plain : std::string();
}

CsvTable load_case_series(const std::string& dir, const CaseEntry& entry) {
  try {
    const std::string path = case_series_path(dir, entry);
    if (path.empty()) return {};
    if (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0)
      return parse_csv(gzip_decompress(read_text_file(path), kMaxInputFileBytes), path);
    return read_csv(path);
  } catch (const std::exception&) {
    return {};
  }
}

std::string canonical_key_values(const std::string& text) {
  std::map<std::string, std::string> items;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t end = std::min(text.find(';', at), text.size());
    const std::string item = text.substr(at, end - at);
    if (!item.empty()) {
      const size_t eq = item.find('=');
      std::string value = eq == std::string::npos ? std::string() : item.substr(eq + 1);
      double v = 0;
      if (try_parse_number(value, v)) value = format_short(v);
      items[item.substr(0, eq)] = value;
    }
    at = end + 1;
  }
  std::string out;
  for (const auto& [k, v] : items) out += (out.empty() ? "" : ";") + k + "=" + v;
  return out;
}

bool same_key_values(const std::string& a, const std::string& b) {
  return a == b || canonical_key_values(a) == canonical_key_values(b);
}

}  // namespace cstab

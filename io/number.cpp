#include "io/number.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>

#include "core/format.hpp"
#include "core/params.hpp"

namespace cstab {

std::string number_cell(double v) { return std::isnan(v) ? std::string() : format_exact(v); }

std::string count_cell(long n) { return n < 0 ? std::string() : std::to_string(n); }

std::string plot_cell(double v) {
  if (!std::isfinite(v)) return "?";
  char text[32];
  std::snprintf(text, sizeof text, "%.7g", v);
  return text;
}

std::string log_plot_cell(double v) { return v > 0 ? plot_cell(v) : "?"; }

std::string csv_at_plot_precision(const std::string& csv) {
  std::string out;
  out.reserve(csv.size() / 2);
  size_t at = csv.find('\n');
  out.append(csv, 0, at == std::string::npos ? csv.size() : at + 1);
  while (at != std::string::npos && at + 1 < csv.size()) {
    const size_t begin = at + 1;
    at = csv.find_first_of(",\n", begin);
    const std::string cell = csv.substr(begin, (at == std::string::npos ? csv.size() : at) - begin);
    double v = 0;
    out += try_parse_number(cell, v) && std::isfinite(v) ? plot_cell(v) : cell;
    if (at != std::string::npos) out += csv[at];
  }
  return out;
}

bool try_parse_number(const std::string& text, double& value) {
  size_t begin = 0, end = text.size();
  while (begin < end && (text[begin] == ' ' || text[begin] == '\t')) ++begin;
  while (end > begin && (text[end - 1] == ' ' || text[end - 1] == '\t')) --end;
  const std::string_view cell = std::string_view(text).substr(begin, end - begin);
  // Decimal (core/params.hpp: is_decimal_number), or the infinities and NaN
  // format_exact writes; not the rest of what strtod reads (hex floats,
  // "infinity", "nan(...)").
  if (cell == "inf" || cell == "+inf") {
    value = std::numeric_limits<double>::infinity();
    return true;
  }
  if (cell == "-inf") {
    value = -std::numeric_limits<double>::infinity();
    return true;
  }
  if (cell == "nan") {
    value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (!is_decimal_number(cell)) return false;
  value = std::strtod(text.c_str() + begin, nullptr);  // stops at a trailing blank
  return true;
}

double parse_number(const std::string& text) {
  double v = std::numeric_limits<double>::quiet_NaN();
  return try_parse_number(text, v) ? v : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace cstab

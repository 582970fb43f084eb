#include "io/number.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "core/format.hpp"

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

bool try_parse_number(const std::string& text, double& value) {
  const char* begin = text.c_str();
  while (*begin == ' ' || *begin == '\t') ++begin;
  if (!*begin) return false;
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin) return false;
  while (*end == ' ' || *end == '\t') ++end;
  if (*end) return false;
  value = v;
  return true;
}

double parse_number(const std::string& text) {
  double v = std::numeric_limits<double>::quiet_NaN();
  return try_parse_number(text, v) ? v : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace cstab

#include "core/params.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/format.hpp"

namespace cstab {

bool is_decimal_number(std::string_view text) {
  size_t i = 0;
  auto digits = [&] {
    const size_t from = i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i;
    return i - from;
  };
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  size_t mantissa = digits();
  if (i < text.size() && text[i] == '.') {
    ++i;
    mantissa += digits();
  }
  if (mantissa == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    if (digits() == 0) return false;
  }
  return i == text.size();
}

double parse_finite_double(const std::string& text, const std::string& what) {
  if (text.empty()) throw UsageError(what + ": empty value, expected a number");
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  // strtod also reads blanks, hex floats ("0x1p-3"), "infinity" and
  // "nan(...)"; a number here is decimal and nothing else.
  const bool whole = end == begin + text.size() && !std::isspace(static_cast<unsigned char>(text.front()));
  if (!is_decimal_number(text)) {
    if (whole && !std::isfinite(value) && text.find_first_of("xX") == std::string::npos)
      throw UsageError(what + ": '" + text + "' is not a finite number");
    throw UsageError(what + ": '" + text + "' is not a number");
  }
  if (!std::isfinite(value))
    throw UsageError(what + ": '" + text + "' is not a finite number");
  return value;
}

std::string param_value_problem(const ParamSpec& spec, double value) {
  if (std::string bad = bound_violation(spec, value); !bad.empty()) return bad;
  if (spec.integer && value != std::floor(value)) return "must be a whole number";
  if (!(value <= spec.max_value)) return "must be <= " + format_short(spec.max_value);
  return "";
}

Params Params::resolve(const std::vector<ParamSpec>& specs,
                       const std::vector<std::pair<std::string, std::string>>& given,
                       const std::string& method_name) {
  return resolve_for(specs, given, "--param", "method '" + method_name + "'");
}

namespace {

// "a (> 0), b (an integer in [1, 10])": the names a message offers instead.
std::string known_params(const std::vector<ParamSpec>& specs) {
  std::string known;
  for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name + " (" + bound_text(s) + ")";
  return known.empty() ? "none" : known;
}

}  // namespace

Params Params::resolve_for(const std::vector<ParamSpec>& specs,
                           const std::vector<std::pair<std::string, std::string>>& given, const std::string& flag,
                           const std::string& owner) {
  Params p;
  for (const auto& s : specs) p.values_.emplace_back(s.name, s.default_value);
  for (const auto& given_pair : given) {
    // Plain references: clang < 16 cannot capture structured bindings.
    const std::string& name = given_pair.first;
    const std::string& text = given_pair.second;
    auto it = std::find_if(specs.begin(), specs.end(),
                           [&](const ParamSpec& s) { return s.name == name; });
    if (it == specs.end())
      throw UsageError(flag + " " + name + ": unknown parameter for " + owner + " (known: " + known_params(specs) +
                       ")");
    if (std::find(p.given_.begin(), p.given_.end(), name) != p.given_.end())
      throw UsageError(flag + " " + name + ": given more than once");
    double value = 0;
    try {
      value = parse_finite_double(text, flag + " " + name);
    } catch (const UsageError& e) {
      throw UsageError(std::string(e.what()) + " (" + name + " must be " + bound_text(*it) + ")");
    }
    const std::string problem = param_value_problem(*it, value);
    if (!problem.empty()) throw UsageError(flag + " " + name + "=" + text + ": " + problem);
    for (auto& [n, v] : p.values_)
      if (n == name) v = value;
    p.given_.push_back(name);
  }
  return p;
}

std::string param_line(const ParamSpec& spec) {
  return spec.name + "=" + format_short(spec.default_value) + "  (" + bound_text(spec) + ") " + spec.description;
}

std::string bound_text(const ParamSpec& spec) {
  switch (spec.bound) {
    case Bound::kPositive: return "> 0";
    case Bound::kNonNegative: return ">= 0";
    case Bound::kRange: return "in [" + format_short(spec.lower) + ", " + format_short(spec.upper) + "]";
    case Bound::kInteger:
      return "an integer in [" + format_short(spec.lower) + ", " + format_short(spec.upper) + "]";
    default: return "any";
  }
}

std::string bound_violation(const ParamSpec& spec, double value) {
  bool ok = true;
  switch (spec.bound) {
    case Bound::kPositive: ok = value > 0; break;
    case Bound::kNonNegative: ok = value >= 0; break;
    case Bound::kRange: ok = value >= spec.lower && value <= spec.upper; break;
    case Bound::kInteger: ok = value >= spec.lower && value <= spec.upper && value == std::floor(value); break;
    default: break;
  }
  return ok ? "" : "must be " + bound_text(spec);
}

double Params::get(const std::string& name) const {
  for (const auto& [n, v] : values_)
    if (n == name) return v;
  throw std::logic_error("parameter not declared: " + name);
}

bool Params::has(const std::string& name) const {
  return std::any_of(values_.begin(), values_.end(), [&](const auto& nv) { return nv.first == name; });
}

std::string Params::describe() const {
  std::string out;
  for (const auto& [n, v] : values_) {
    if (!out.empty()) out += ';';
    out += n + "=" + format_short(v);
  }
  return out;
}

const ParamSpec* find_gain(const std::vector<ParamSpec>& specs) {
  for (const auto& s : specs)
    if (s.role != ParamRole::kSetting) return &s;
  return nullptr;
}

double gain_rate(const ParamSpec& gain, double value) {
  return gain.role == ParamRole::kTimeScale ? 1.0 / value : value;
}

}  // namespace cstab

// Parameters of a method ("--param name=value") or of a problem
// ("--problem-param name=value"): a declared list of named real values with
// defaults and bounds, parsed once before a run starts.
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cstab {

// Thrown for any bad input a user can fix (unknown names, bad numbers, ...).
// The CLI turns it into a one-line message and exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// kRange: a value in [lower, upper]; kInteger: an integer in [lower, upper].
enum class Bound { kAny, kPositive, kNonNegative, kRange, kInteger };

// What a parameter is to the harness, so that stability maps, stress tables
// and the report find "the gain" of any method without knowing its names.
enum class ParamRole {
  kSetting,    // anything else
  kRate,       // a stabilization gain that is a decay rate (1/s): lambda, alpha
  kTimeScale,  // a stabilization gain that is a time scale (s): rate = 1 / value
};

struct ParamSpec {
  std::string name;
  double default_value;
  Bound bound;
  std::string description;
  ParamRole role = ParamRole::kSetting;
  // Parameters that take the same value when this gain is swept (e.g.
  // Baumgarte's beta with alpha: the repeated root -alpha).
  std::vector<std::string> swept_with = {};
  // A count (an iteration limit): a whole number no larger than max_value,
  // checked before anything converts it to an int.
  bool integer = false;
  double max_value = std::numeric_limits<double>::infinity();
  double lower = 0, upper = 0;  // kRange, kInteger
};

// A setting in the closed interval [lower, upper] (integer: whole numbers only).
inline ParamSpec ranged_param(std::string name, double default_value, double lower, double upper,
                              std::string description, bool integer = false) {
  ParamSpec s{std::move(name), default_value, integer ? Bound::kInteger : Bound::kRange, std::move(description)};
  s.lower = lower;
  s.upper = upper;
  return s;
}

// The bound in words ("> 0", "in [0, 1]", "an integer in [1, 100]"; "any").
std::string bound_text(const ParamSpec& spec);
// "" if `value` satisfies the spec's bound; otherwise "must be <bound_text>".
std::string bound_violation(const ParamSpec& spec, double value);
// Why `value` is not allowed for `spec` (its bound, then `integer` and
// `max_value`: "must be > 0", "must be a whole number", ...); "" if it is.
std::string param_value_problem(const ParamSpec& spec, double value);

// "NAME=DEFAULT  (BOUND) DESCRIPTION", one line of `cstab list`.
std::string param_line(const ParamSpec& spec);

// The method's gain: its first kRate or kTimeScale parameter (nullptr if none).
const ParamSpec* find_gain(const std::vector<ParamSpec>& specs);
// The decay rate a gain value implies (value, or 1 / value for a time scale).
double gain_rate(const ParamSpec& gain, double value);

// Resolved parameter values: every declared name has a value.
class Params {
 public:
  Params() = default;

  // Checks `given` (name, value text) against `specs`; throws UsageError naming
  // the offending parameter.
  static Params resolve(const std::vector<ParamSpec>& specs,
                        const std::vector<std::pair<std::string, std::string>>& given,
                        const std::string& method_name);
  // The same for any owner: `flag` starts each message ("--problem-param"),
  // `owner` names whose parameters they are ("problem 'pendulum'").
  static Params resolve_for(const std::vector<ParamSpec>& specs,
                            const std::vector<std::pair<std::string, std::string>>& given, const std::string& flag,
                            const std::string& owner);

  double get(const std::string& name) const;
  bool has(const std::string& name) const;
  // "a=1;b=2" in declaration order, for the summary's `params` column.
  std::string describe() const;
  const std::vector<std::pair<std::string, double>>& values() const { return values_; }

 private:
  std::vector<std::pair<std::string, double>> values_;
  std::vector<std::string> given_;
};

// The one number syntax of every flag and file: an optional sign, decimal
// digits with an optional point, an optional decimal exponent ("1e-3",
// "-0.5", "2.", ".25", "1E+06"). No blanks, no hex floats ("0x1p-3"), no
// "infinity" or "nan(...)": what strtod accepts beyond this is refused.
bool is_decimal_number(std::string_view text);

// Strict number parsing: the whole text must be a finite decimal number
// (is_decimal_number).
double parse_finite_double(const std::string& text, const std::string& what);

}  // namespace cstab

#include "cli/args.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>
#include <stdexcept>

#include "core/problem.hpp"

namespace cstab::cli {

Args::Args(CLI::App& command) : app_(&command) {}

Args& Args::add(const std::string& flag, const std::string& metavar, const std::string& help, bool needed,
                bool repeatable) {
  Declared& d = declared_[flag];
  d.repeatable = repeatable;
  // Every occurrence takes exactly one value; all of them are kept, and
  // check() rejects a second one where only one is allowed (so the message
  // is ours, naming the option).
  CLI::Option* opt = app_->add_option(flag, values_[flag], help);
  opt->type_name(metavar)->expected(1)->allow_extra_args(false)->multi_option_policy(
      CLI::MultiOptionPolicy::TakeAll);
  if (needed) opt->required();
  return *this;
}

Args& Args::value(const std::string& flag, const std::string& metavar, const std::string& help,
                  const std::string& fallback) {
  add(flag, metavar, fallback.empty() ? help : help + " (default " + fallback + ")", false, false);
  declared_[flag].fallback = fallback;
  return *this;
}

Args& Args::required(const std::string& flag, const std::string& metavar, const std::string& help) {
  return add(flag, metavar, help, true, false);
}

Args& Args::repeatable(const std::string& flag, const std::string& metavar, const std::string& help) {
  return add(flag, metavar, help + " (repeatable)", false, true);
}

Args& Args::flag(const std::string& flag, const std::string& help) {
  Declared& d = declared_[flag];
  d.is_switch = true;
  // --flag=value is an error, not a way to switch it off.
  app_->add_flag(flag, d.set, help)->disable_flag_override();
  return *this;
}

Args& Args::positional(const std::string& name, const std::string& help, bool needed, bool many) {
  declared_[name].repeatable = many;
  // One value, or (many) every remaining one; an optional one is simply
  // not required (CLI11 fills no positional that expects 0 values).
  CLI::Option* opt = app_->add_option(name, values_[name], help)->type_name("");
  if (!many) opt->expected(1)->allow_extra_args(false);
  if (needed) opt->required();
  return *this;
}

void Args::check() const {
  for (const auto& [name, values] : values_) {
    // CLI11 gives an option without a value the next argument, even an
    // option ("--blowup --out DIR", "--blowup= --out DIR").
    for (const auto& v : values) {
      const std::string word = v.substr(0, v.find('='));
      if (name.rfind("--", 0) == 0 && word.rfind("-", 0) == 0 &&
          (declared_.count(word) || word == "--help" || word == "-h"))
        throw UsageError(name + ": missing value (the next argument, " + v + ", is an option)");
    }
    if (values.size() > 1 && !declared(name).repeatable) throw UsageError(name + ": given more than once");
  }
}

const Args::Declared& Args::declared(const std::string& name) const {
  auto it = declared_.find(name);
  if (it == declared_.end()) throw std::logic_error("option not declared: " + name);
  return it->second;
}

bool Args::has(const std::string& name) const {
  const Declared& d = declared(name);
  if (d.is_switch) return d.set;
  return !values_.at(name).empty();
}

std::string Args::get(const std::string& name) const {
  const Declared& d = declared(name);
  const auto& v = values_.at(name);
  return v.empty() ? d.fallback : v.front();
}

std::string Args::require(const std::string& name) const {
  const auto& v = values_.at(name);
  if (v.empty()) throw UsageError(name + ": required");
  if (v.front().empty()) throw UsageError(name + ": empty value");
  return v.front();
}

std::vector<std::string> Args::all(const std::string& name) const {
  declared(name);
  return values_.at(name);
}

double Args::number(const std::string& name) const {
  const std::string text = get(name);
  if (text.empty() && !has(name)) throw std::logic_error(name + ": no value and no default");
  return parse_finite_double(text, name);
}

long Args::integer(const std::string& name) const {
  const std::string text = get(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  // strtol skips leading blanks; an integer is a decimal number without
  // point or exponent, nothing around it.
  if (text.empty() || *end != '\0' || errno || !is_decimal_number(text) ||
      text.find_first_of(".eE") != std::string::npos)
    throw UsageError(name + ": '" + text + "' is not an integer");
  return v;
}

std::vector<double> Args::number_list(const std::string& name) const {
  std::vector<double> out;
  for (const auto& text : all(name)) {
    size_t start = 0;
    while (start <= text.size()) {
      const size_t comma = text.find(',', start);
      const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      out.push_back(parse_finite_double(item, name));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return out;
}

double Args::end_time(const std::string& name, const ProblemInfo& problem) const {
  return resolve_end_time(require(name), problem, name);
}

double resolve_end_time(const std::string& text, const ProblemInfo& problem, const std::string& option) {
  if (text == "ref") return problem.reference_time > 0 ? problem.reference_time : problem.default_t_end;
  if (text == "default") return problem.default_t_end;
  return parse_finite_double(text, option);
}

std::vector<std::pair<std::string, std::string>> Args::pairs(const std::string& name) const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& kv : all(name)) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError(name + " " + kv + ": expected name=value");
    out.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
  }
  return out;
}

}  // namespace cstab::cli

// One command's options, declared once: the declarations make the CLI11
// parser and the command's --help. Values are kept as text and converted by
// the readers, which name the option in every error (UsageError, exit 2).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/params.hpp"

namespace CLI {
class App;
}  // namespace CLI

namespace cstab {
struct ProblemInfo;
}  // namespace cstab

namespace cstab::cli {

class Args {
 public:
  // Declares options on `command` (a CLI11 subcommand).
  explicit Args(CLI::App& command);
  Args(const Args&) = delete;
  Args& operator=(const Args&) = delete;

  // --- declarations. `metavar` names the value in --help; `help` is the
  // one-line description; `fallback` is the value used when the option is
  // not given (listed in --help as the default).
  Args& value(const std::string& flag, const std::string& metavar, const std::string& help,
              const std::string& fallback = "");
  // Must be given (CLI11 reports it missing before the command runs).
  Args& required(const std::string& flag, const std::string& metavar, const std::string& help);
  // May be given more than once; all() returns every value in order.
  Args& repeatable(const std::string& flag, const std::string& metavar, const std::string& help);
  // Takes no value.
  Args& flag(const std::string& flag, const std::string& help);
  // A positional argument; `many`: takes every remaining one.
  Args& positional(const std::string& name, const std::string& help, bool needed, bool many = false);

  // --- after parsing (also after a parse error: its causes come first).
  // Rejects a non-repeatable option given twice and an option that took
  // the next option as its value.
  void check() const;

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;  // the value, else the declared fallback
  std::string require(const std::string& name) const;
  std::vector<std::string> all(const std::string& name) const;

  // Finite numbers (no NaN, no inf, no trailing text); without a value, the
  // declared fallback.
  double number(const std::string& name) const;
  long integer(const std::string& name) const;
  // Comma-separated, across every occurrence.
  std::vector<double> number_list(const std::string& name) const;
  // resolve_end_time (below) of the value.
  double end_time(const std::string& name, const ProblemInfo& problem) const;
  // --param name=value pairs.
  std::vector<std::pair<std::string, std::string>> pairs(const std::string& name) const;

  CLI::App& app() const { return *app_; }

 private:
  struct Declared {
    std::string fallback;
    bool repeatable = false;
    bool is_switch = false;
    bool set = false;  // a switch that was given
  };
  Args& add(const std::string& flag, const std::string& metavar, const std::string& help, bool needed,
            bool repeatable);
  const Declared& declared(const std::string& name) const;

  CLI::App* app_;
  std::map<std::string, std::vector<std::string>> values_;  // node-based: CLI11 keeps pointers into it
  std::map<std::string, Declared> declared_;
};

// `text` as an end time for `problem`: a finite number, "ref" (the
// problem's reference time, or its default horizon if it has none: as
// matrix files read t_end = "ref") or "default" (its default horizon).
// Errors name `option`.
double resolve_end_time(const std::string& text, const ProblemInfo& problem, const std::string& option);

}  // namespace cstab::cli

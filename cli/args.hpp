// A small strict flag parser: "--name value" pairs, repeatable where allowed,
// every flag validated; unknown flags are errors.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/params.hpp"

namespace cstab::cli {

class Args {
 public:
  // `flags`: accepted value flags; `switches`: accepted flags without value;
  // `repeatable`: value flags that may appear more than once.
  Args(const std::vector<std::string>& argv, const std::set<std::string>& flags,
       const std::set<std::string>& switches = {}, const std::set<std::string>& repeatable = {});

  bool has(const std::string& flag) const { return values_.count(flag) || switches_.count(flag); }
  std::string get(const std::string& flag, const std::string& fallback = "") const;
  std::string require(const std::string& flag) const;
  std::vector<std::string> all(const std::string& flag) const;
  const std::vector<std::string>& positional() const { return positional_; }

  double number(const std::string& flag, double fallback) const;
  long integer(const std::string& flag, long fallback) const;
  std::vector<double> number_list(const std::string& flag) const;

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::set<std::string> switches_;
  std::vector<std::string> positional_;
};

}  // namespace cstab::cli

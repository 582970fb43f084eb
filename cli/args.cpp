#include "cli/args.hpp"

#include <cerrno>
#include <cstdlib>

namespace cstab::cli {

Args::Args(const std::vector<std::string>& argv, const std::set<std::string>& flags,
           const std::set<std::string>& switches, const std::set<std::string>& repeatable) {
  for (size_t i = 0; i < argv.size(); ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0) {
      positional_.push_back(a);
      continue;
    }
    std::string value;
    bool inline_value = false;
    if (auto eq = a.find('='); eq != std::string::npos) {
      value = a.substr(eq + 1);
      a = a.substr(0, eq);
      inline_value = true;
    }
    if (switches.count(a)) {
      if (inline_value) throw UsageError(a + ": takes no value");
      switches_.insert(a);
      continue;
    }
    if (!flags.count(a)) throw UsageError(a + ": unknown option");
    if (!inline_value) {
      if (i + 1 >= argv.size()) throw UsageError(a + ": missing value");
      value = argv[++i];
    }
    auto& slot = values_[a];
    if (!slot.empty() && !repeatable.count(a)) throw UsageError(a + ": given more than once");
    slot.push_back(value);
  }
}

std::string Args::get(const std::string& flag, const std::string& fallback) const {
  auto it = values_.find(flag);
  return it == values_.end() ? fallback : it->second.front();
}

std::string Args::require(const std::string& flag) const {
  auto it = values_.find(flag);
  if (it == values_.end()) throw UsageError(flag + ": required");
  if (it->second.front().empty()) throw UsageError(flag + ": empty value");
  return it->second.front();
}

std::vector<std::string> Args::all(const std::string& flag) const {
  auto it = values_.find(flag);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

double Args::number(const std::string& flag, double fallback) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return fallback;
  return parse_finite_double(it->second.front(), flag);
}

long Args::integer(const std::string& flag, long fallback) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return fallback;
  const std::string& text = it->second.front();
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno) throw UsageError(flag + ": '" + text + "' is not an integer");
  return v;
}

std::vector<double> Args::number_list(const std::string& flag) const {
  std::vector<double> out;
  for (const auto& text : all(flag)) {
    size_t start = 0;
    while (start <= text.size()) {
      const size_t comma = text.find(',', start);
      const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      out.push_back(parse_finite_double(item, flag));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return out;
}

}  // namespace cstab::cli

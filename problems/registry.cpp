// Adding a problem: a class in problems/ and one line in all_problems().
#include "problems/registry.hpp"

#include "methods/dispatch.hpp"
#include "problems/wheel.hpp"

namespace cstab {

const std::vector<std::unique_ptr<Problem>>& all_problems() {
  static const std::vector<std::unique_ptr<Problem>> list = [] {
    std::vector<std::unique_ptr<Problem>> v;
    v.push_back(std::make_unique<ProblemAdapter<Wheel>>(Wheel{}));
    return v;
  }();
  return list;
}

const Problem& find_problem(const std::string& name) {
  for (const auto& p : all_problems())
    if (p->info().name == name) return *p;
  std::string known;
  for (const auto& p : all_problems()) known += (known.empty() ? "" : ", ") + p->info().name;
  throw UsageError("--problem " + name + ": unknown problem (known: " + known + ")");
}

}  // namespace cstab

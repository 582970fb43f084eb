// The problem list at run time: the built-in catalog, then the problems
// plugins add (plugin/loader.cpp).
#include "problems/registry.hpp"

namespace cstab {

namespace {

struct ProblemRegistry {
  std::vector<std::unique_ptr<Problem>> problems = builtin_problems();
  std::vector<std::string> origins = std::vector<std::string>(problems.size());
};

ProblemRegistry& registry() {
  static ProblemRegistry r;
  return r;
}

}  // namespace

const std::vector<std::unique_ptr<Problem>>& all_problems() { return registry().problems; }

const Problem& find_problem(const std::string& name) {
  for (const auto& p : all_problems())
    if (p->info().name == name) return *p;
  std::string known;
  for (const auto& p : all_problems()) known += (known.empty() ? "" : ", ") + p->info().name;
  throw UsageError("--problem " + name + ": unknown problem (known: " + known + ")");
}

void add_problem(std::unique_ptr<Problem> problem, const std::string& origin) {
  ProblemRegistry& r = registry();
  if (!problem || problem->info().name.empty()) throw UsageError("a problem without a name");
  const std::string& name = problem->info().name;
  for (std::size_t i = 0; i < r.problems.size(); ++i)
    if (r.problems[i]->info().name == name)
      throw UsageError("problem '" + name + "' is already defined (" +
                       (r.origins[i].empty() ? std::string("built in") : "by " + r.origins[i]) + ")");
  r.problems.push_back(std::move(problem));
  r.origins.push_back(origin);
}

const std::string& problem_origin(const std::string& name) {
  static const std::string none;
  const ProblemRegistry& r = registry();
  for (std::size_t i = 0; i < r.problems.size(); ++i)
    if (r.problems[i]->info().name == name) return r.origins[i];
  return none;
}

}  // namespace cstab

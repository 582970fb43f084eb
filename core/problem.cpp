#include "core/problem.hpp"

#include <stdexcept>

namespace cstab {

std::unique_ptr<Problem> problem_variant(const Problem& base,
                                         const std::vector<std::pair<std::string, std::string>>& given,
                                         std::string* values) {
  const Params params =
      Params::resolve_for(base.problem_params(), given, "--problem-param", "problem '" + base.info().name + "'");
  if (values) *values = params.describe();
  if (given.empty()) return nullptr;
  auto variant = base.with_params(params);
  if (!variant) throw std::logic_error("problem '" + base.info().name + "' declares parameters but no with_params");
  return variant;
}

}  // namespace cstab

// The list of problems.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/problem.hpp"

namespace cstab {

const std::vector<std::unique_ptr<Problem>>& all_problems();
const Problem& find_problem(const std::string& name);  // throws UsageError

}  // namespace cstab

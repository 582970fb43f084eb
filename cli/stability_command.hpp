#pragma once

#include <string>
#include <vector>

namespace cstab::cli {

// cstab stability: step x gain maps and measured stability boundaries.
int cmd_stability(const std::vector<std::string>& argv);

}  // namespace cstab::cli

// cstab gate: checks a matrix results folder against a thresholds file.
#pragma once

#include <string>
#include <vector>

namespace cstab::cli {

int cmd_gate(const std::vector<std::string>& argv);

}  // namespace cstab::cli

#pragma once

#include <string>
#include <vector>

namespace cstab::cli {

std::string usage();
// Runs a subcommand; returns the exit code. Throws UsageError on bad input.
int dispatch(const std::string& command, const std::vector<std::string>& args);

}  // namespace cstab::cli

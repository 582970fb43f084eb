// cstab matrix / merge / report: the benchmark matrix commands.
#pragma once

#include <string>
#include <vector>

namespace cstab::cli {

int cmd_matrix(const std::vector<std::string>& argv);
int cmd_merge(const std::vector<std::string>& argv);
int cmd_report(const std::vector<std::string>& argv);

// The matrix `cstab matrix` runs without a FILE.
const std::string& default_matrix_text();

}  // namespace cstab::cli

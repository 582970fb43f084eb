// cstab matrix / merge / report: the benchmark matrix commands.
#pragma once

#include <string>

namespace cstab::cli {

class Args;

void declare_matrix(Args& args);
int cmd_matrix(const Args& args);
void declare_merge(Args& args);
int cmd_merge(const Args& args);
void declare_report(Args& args);
int cmd_report(const Args& args);

// The matrix `cstab matrix` runs without a FILE.
const std::string& default_matrix_text();

}  // namespace cstab::cli

// cstab gate: checks a matrix results folder against a thresholds file.
#pragma once

namespace cstab::cli {

class Args;

void declare_gate(Args& args);
int cmd_gate(const Args& args);

}  // namespace cstab::cli

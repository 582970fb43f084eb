#pragma once

namespace cstab::cli {

class Args;

// cstab stability: step x gain maps and measured stability boundaries.
void declare_stability(Args& args);
int cmd_stability(const Args& args);

}  // namespace cstab::cli

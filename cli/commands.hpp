// The cstab command line: one CLI11 subcommand per command, each declared
// once (cli/*_command.cpp); the declarations parse the arguments and make
// `cstab --help`, `cstab help [COMMAND]` and `cstab COMMAND --help`.
#pragma once

#include <string>
#include <vector>

namespace cstab::cli {

class Args;

// Parses `args` (argv without the program name), runs the command and
// returns the exit code: 0 success, 2 bad input (one line on stderr naming
// what is wrong, nothing written), 1 internal error; some commands add
// their own (gate 1: a check failed; merge 3: cases missing).
int main_command(const std::vector<std::string>& args);

// `cstab --help`: the commands with a one-line description each.
std::string usage();
// `cstab COMMAND --help`; throws UsageError for an unknown command.
std::string command_help(const std::string& command);

// The options `run` and `stability` share, spelled and described alike:
// --problem, --method, --formulation, --param, --integrator, --t-end.
void declare_case_options(Args& args);

// Commands in files of their own: declare_X declares the options of
// `cstab X`, cmd_X runs it.
// cstab gate (gate_command.cpp): checks a matrix results folder against a
// thresholds file.
void declare_gate(Args& args);
int cmd_gate(const Args& args);
// cstab stability (stability_command.cpp): step x gain maps and measured
// stability boundaries.
void declare_stability(Args& args);
int cmd_stability(const Args& args);
// cstab score (score_command.cpp): the metrics of run for a trajectory
// computed elsewhere.
void declare_score(Args& args);
int cmd_score(const Args& args);
// cstab check (check_command.cpp): the conformance checks on plugins' methods
// and problems, or on chosen ones.
void declare_check(Args& args);
int cmd_check(const Args& args);
// cstab tune (tune_command.cpp): the cheapest gain and step/tolerance for a target.
void declare_tune(Args& args);
int cmd_tune(const Args& args);

}  // namespace cstab::cli

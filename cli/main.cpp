// cstab: command-line entry point. The commands and their options are
// declared in cli/commands.cpp and cli/*_command*.cpp; `cstab --help` and
// `cstab COMMAND --help` print them (docs/cli.md has them all).
#include <csignal>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "io/csv.hpp"

namespace {

// Ctrl-C, SIGTERM, SIGHUP: remove the temporaries of unfinished output
// files, then die of the signal as usual (`cstab matrix` installs its own
// handlers while it runs cases).
extern "C" void on_fatal_signal(int sig) {
  cstab::remove_temporary_files();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

int main(int argc, char** argv) {
  for (int sig : {SIGINT, SIGTERM, SIGHUP})
    if (std::signal(sig, on_fatal_signal) == SIG_IGN) std::signal(sig, SIG_IGN);  // nohup, background jobs
  return cstab::cli::main_command(std::vector<std::string>(argv + 1, argv + argc));
}

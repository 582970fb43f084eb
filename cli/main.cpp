// cstab: command-line entry point.
//   cstab list
//   cstab run --problem P --method M [--formulation F] [--param k=v ...]
//             --integrator I (--step H | --rtol R --atol A) --t-end T
//             [--times t1,t2,...] [--sample-every DT] [--ref-time T]
//             [--blowup B] [--observe-every N] --out DIR
#include <csignal>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "io/csv.hpp"
#include "core/params.hpp"

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
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
    std::cout << cstab::cli::usage();
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  try {
    return cstab::cli::dispatch(command, args);
  } catch (const cstab::UsageError& e) {
    std::cerr << "cstab " << command << ": error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "cstab " << command << ": error: " << e.what() << "\n";
    return 1;
  }
}

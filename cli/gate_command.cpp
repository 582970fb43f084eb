// cstab gate [--thresholds FILE] [--csv OUT] DIR
//   prints one row per check (value, threshold, margin, pass/fail); exit 0
//   only if every check passes, 1 if one fails, 2 for bad input.
// cstab gate --update [--factor F] [--time-factor T] [--recovery-factor R] [--thresholds FILE] DIR
//   re-baselines the bounds the file sets from DIR and prints what changed.
// cstab gate --init FILE [--factor F] DIR
//   writes a new thresholds file with every completed case of DIR.
#include "cli/gate_command.hpp"

#include <filesystem>
#include <iostream>

#include "cli/args.hpp"
#include "io/csv.hpp"
#include "core/format.hpp"
#include "gate/gate.hpp"

namespace cstab::cli {

namespace {

// The repository's thresholds file, used when --thresholds is not given.
const char* kDefaultThresholds = CSTAB_SOURCE_DIR "/matrices/gate-thresholds.csv";

}  // namespace

int cmd_gate(const std::vector<std::string>& argv) {
  Args args(argv, {"--thresholds", "--csv", "--factor", "--time-factor", "--recovery-factor", "--init"}, {"--update"});
  if (args.positional().size() != 1)
    throw UsageError(args.positional().empty() ? "expected the results folder DIR (usage: cstab gate [--thresholds FILE] DIR)"
                                               : "expected one results folder, got " +
                                                     std::to_string(args.positional().size()) + " arguments");
  const std::string dir = args.positional()[0];
  if (!std::filesystem::is_directory(dir)) throw UsageError(dir + ": no such results folder");
  GateFactors factors;
  factors.value = args.number("--factor", factors.value);
  factors.time_ratio = args.number("--time-factor", factors.time_ratio);
  factors.recovery = args.number("--recovery-factor", factors.recovery);

  if (args.has("--init")) {
    if (args.has("--update") || args.has("--thresholds") || args.has("--csv"))
      throw UsageError("--init FILE: writes a new file; not with --update, --thresholds or --csv");
    const std::string path = args.get("--init");
    if (std::filesystem::exists(path)) throw UsageError("--init " + path + ": exists (use --update to re-baseline it)");
    const ThresholdsFile file = initial_thresholds(dir, factors, path);
    try {
      write_file_atomic(path, thresholds_text(file));
    } catch (const std::exception& e) {
      throw UsageError("--init " + path + ": " + e.what());
    }
    std::cout << "gate: wrote " << path << " with " << file.rows.size() << " cases from " << dir
              << " (factor " << format_short(factors.value) << ")\n";
    return 0;
  }

  const std::string path = args.get("--thresholds", kDefaultThresholds);
  ThresholdsFile file = read_thresholds_file(path);

  if (args.has("--update")) {
    if (args.has("--csv")) throw UsageError("--csv: not with --update");
    std::vector<std::string> notes;
    const auto changes = update_thresholds(file, dir, factors, notes);
    for (const auto& n : notes) std::cout << "note: " << n << "\n";
    for (const auto& c : changes)
      std::cout << c.case_label << "  " << c.column << ": " << (c.old_value.empty() ? "(empty)" : c.old_value)
                << " -> " << c.new_value << "\n";
    if (!changes.empty()) {
      try {
        write_file_atomic(path, thresholds_text(file));
      } catch (const std::exception& e) {
        throw UsageError("--thresholds " + path + ": cannot write: " + e.what());
      }
    }
    std::cout << "gate: " << changes.size() << " thresholds changed in " << path << " (factor "
              << format_short(factors.value) << ", time factor " << format_short(factors.time_ratio)
              << ", recovery factor " << format_short(factors.recovery) << ")\n";
    return 0;
  }

  if (args.has("--factor") || args.has("--time-factor") || args.has("--recovery-factor"))
    throw UsageError("--factor/--time-factor/--recovery-factor: only with --update or --init");
  const GateOutcome outcome = evaluate_gate(file, dir);
  std::cout << format_gate_table(outcome);
  std::cout << "thresholds " << path << ", results " << dir << ": " << (outcome.failed ? "FAILED" : "passed") << "\n";
  if (args.has("--csv")) {
    try {
      write_file_atomic(args.get("--csv"), gate_csv(outcome));
    } catch (const std::exception& e) {
      throw UsageError("--csv " + args.get("--csv") + ": " + e.what());
    }
  }
  return outcome.failed ? 1 : 0;
}

}  // namespace cstab::cli

// cstab gate [--thresholds FILE] [--csv OUT] DIR
//   prints one row per check (value, threshold, margin, pass/fail); exit 0
//   only if every check passes, 1 if one fails, 2 for bad input.
// cstab gate --update [--factor F] [--time-factor T] [--recovery-factor R] [--thresholds FILE] DIR
//   re-baselines the bounds the file sets from DIR and prints what changed.
// cstab gate --init FILE [--factor F] [--time-factor T] [--recovery-factor R] DIR
//   writes a new thresholds file with every completed case of DIR.
// (declare_gate below is what parses them and prints `cstab gate --help`.)
#include "cli/commands.hpp"

#include <filesystem>
#include <memory>
#include <iostream>

#include "cli/args.hpp"
#include "io/csv.hpp"
#include "io/lock.hpp"
#include "core/format.hpp"
#include "gate/gate.hpp"

namespace cstab::cli {

namespace {

// The repository's thresholds file, used when --thresholds is not given.
const char* kDefaultThresholds = CSTAB_SOURCE_DIR "/matrices/gate-thresholds.csv";

}  // namespace

void declare_gate(Args& a) {
  const GateFactors d;
  a.positional("DIR", "a matrix results folder (cstab matrix --out)", true)
      .value("--thresholds", "FILE", "thresholds file (default: matrices/gate-thresholds.csv of the source tree)")
      .value("--csv", "OUT", "also write the table of checks to OUT (CSV)")
      .flag("--update", "re-baseline the bounds the thresholds file sets from DIR, print what changed")
      .value("--init", "FILE", "write a new thresholds file FILE with every completed case of DIR")
      .flag("--add-missing", "append a row (by the rule of --init) for every completed case of DIR no row names")
      .flag("--strict", "also fail (exit 1) when a completed case of DIR has no thresholds row")
      .value("--factor", "F", "--update/--init: upper bounds = measured value x F (>= 1)", format_short(d.value))
      .value("--time-factor", "T", "--update/--init: max_time_ratio = measured ratio x T", format_short(d.time_ratio))
      .value("--recovery-factor", "R", "--update/--init: max_recovery_time = measured time x R",
             format_short(d.recovery));
}

namespace {

// Writes the thresholds file, or says which file could not be written.
void write_thresholds(const std::string& option, const std::string& path, const ThresholdsFile& file) {
  try {
    write_file_atomic(path, thresholds_text(file));
  } catch (const std::exception& e) {
    throw UsageError(option + " " + path + ": cannot write: " + e.what());
  }
}

int gate_init(const Args& args, const std::string& dir, const GateFactors& factors) {
  if (args.has("--update") || args.has("--thresholds") || args.has("--csv"))
    throw UsageError("--init FILE: writes a new file; not with --update, --thresholds or --csv");
  const std::string path = args.get("--init");
  if (std::filesystem::exists(path)) throw UsageError("--init " + path + ": exists (use --update to re-baseline it)");
  const ThresholdsFile file = initial_thresholds(dir, factors, path);
  write_thresholds("--init", path, file);
  std::cout << "gate: wrote " << path << " with " << file.rows.size() << " cases from " << dir << " (factor "
            << format_short(factors.value) << ")\n";
  return 0;
}

int gate_add_missing(const Args& args, const std::string& dir, const GateFactors& factors, const std::string& path,
                     ThresholdsFile& file) {
  if (args.has("--update") || args.has("--csv") || args.has("--strict"))
    throw UsageError("--add-missing: writes the thresholds file; not with --update, --csv or --strict");
  const auto added = add_missing_thresholds(file, dir, factors);
  for (const auto& label : added) std::cout << "added: " << label << "\n";
  if (!added.empty()) write_thresholds("--thresholds", path, file);
  std::cout << "gate: " << added.size() << " rows added to " << path << " (factor " << format_short(factors.value)
            << ")\n";
  return 0;
}

int gate_update(const Args& args, const std::string& dir, const GateFactors& factors, const std::string& path,
                ThresholdsFile& file) {
  if (args.has("--csv")) throw UsageError("--csv: not with --update");
  if (args.has("--strict")) throw UsageError("--strict: not with --update");
  std::vector<std::string> notes;
  const auto changes = update_thresholds(file, dir, factors, notes);
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  for (const auto& c : changes)
    std::cout << c.case_label << "  " << c.column << ": " << (c.old_value.empty() ? "(empty)" : c.old_value) << " -> "
              << c.new_value << "\n";
  if (!changes.empty()) write_thresholds("--thresholds", path, file);
  std::cout << "gate: " << changes.size() << " thresholds changed in " << path << " (factor "
            << format_short(factors.value) << ", time factor " << format_short(factors.time_ratio)
            << ", recovery factor " << format_short(factors.recovery) << ")\n";
  return 0;
}

// The check itself: exit 0 when every row passes (and, with --strict, every
// completed case has a row), 1 otherwise.
int gate_check(const Args& args, const std::string& dir, const std::string& path, const ThresholdsFile& file) {
  if (args.has("--factor") || args.has("--time-factor") || args.has("--recovery-factor"))
    throw UsageError("--factor/--time-factor/--recovery-factor: only with --update, --init or --add-missing");
  if (file.rows.empty())
    throw UsageError(path + ": no thresholds rows: a gate of 0 checks proves nothing (`cstab gate --init` writes "
                            "a first file)");
  const GateOutcome outcome = evaluate_gate(file, dir);
  std::cout << format_gate_table(outcome);
  const bool strict_failed = args.has("--strict") && outcome.unchecked_cases > 0;
  if (strict_failed) {
    std::cout << "--strict: " << outcome.unchecked_cases << " completed cases have no thresholds row "
              << "(`cstab gate --add-missing` adds them):\n";
    for (const auto& u : outcome.unchecked) std::cout << "  unchecked: " << u << "\n";
  }
  const bool failed = outcome.failed > 0 || strict_failed;
  std::cout << "thresholds " << path << ", results " << dir << ": " << (failed ? "FAILED" : "passed") << "\n";
  if (args.has("--csv")) {
    try {
      write_file_atomic(args.get("--csv"), gate_csv(outcome));
    } catch (const std::exception& e) {
      throw UsageError("--csv " + args.get("--csv") + ": " + e.what());
    }
  }
  return failed ? 1 : 0;
}

}  // namespace

int cmd_gate(const Args& args) {
  const std::string dir = args.require("DIR");
  if (!std::filesystem::is_directory(dir)) throw UsageError(dir + ": no such results folder");
  GateFactors factors;
  factors.value = args.number("--factor");
  factors.time_ratio = args.number("--time-factor");
  factors.recovery = args.number("--recovery-factor");
  if (args.has("--init")) return gate_init(args, dir, factors);

  const std::string path = args.has("--thresholds") ? args.get("--thresholds") : kDefaultThresholds;
  ThresholdsFile file = read_thresholds_file(path);
  // A folder a matrix is still writing is not re-baselined from.
  std::unique_ptr<FolderLock> lock;
  if ((args.has("--add-missing") || args.has("--update")) && std::filesystem::is_directory(dir + "/cases"))
    lock = std::make_unique<FolderLock>(dir, "cstab gate");
  if (args.has("--add-missing")) return gate_add_missing(args, dir, factors, path, file);
  if (args.has("--update")) return gate_update(args, dir, factors, path, file);
  return gate_check(args, dir, path, file);
}

}  // namespace cstab::cli

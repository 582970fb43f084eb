// Results you can trust (issue 16): every run ends (step-count guard, step
// limit, default case timeout, bounded stability maps); bad input is
// refused with exit 2 and leaves nothing behind (integer parameters, case
// ids, report on a non-results folder, gate bounds that would overflow,
// malformed cases.csv with file:line:column, --strict / --add-missing,
// numbers that are not decimal); a results folder is locked while a command
// writes it (a refused command leaves no new lock file; merge refuses a
// shard a matrix is writing); a cached case is
// re-verified against the content hashes in its case.txt and rerun, saying
// why, when a file or the record itself is missing, truncated, edited or
// swapped, or was written by an older cstab; a binary that cannot be read
// has the identity "unknown" and nothing is reused as cached.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/params.hpp"
#include "io/csv.hpp"
#include "io/gzip.hpp"
#include "io/hash.hpp"
#include "io/lock.hpp"
#include "io/number.hpp"
#include "matrix/matrix.hpp"
#include "matrix/provenance.hpp"
#include "matrix/results.hpp"
#include "methods/pair.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"

namespace fs = std::filesystem;
using cstab::testing::contains;
using cstab::testing::cstab_cmd;
using cstab::testing::Outcome;
using cstab::testing::quote;
using cstab::testing::Scratch;
using cstab::testing::slurp;

namespace {

// Every file below `dir` with its content, for "nothing changed" checks.
std::string snapshot(const fs::path& dir) {
  std::string s;
  std::error_code ec;
  if (!fs::exists(dir, ec)) return "(none)";
  std::vector<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file()) names.push_back(e.path().string());
  std::sort(names.begin(), names.end());
  for (const auto& n : names) s += n + "\n" + slurp(n) + "\n";
  return s;
}

const char* kRun = "run --problem wheel --method pesterev --integrator rk4 --t-end 0.05 ";

cstab::MatrixCatalog catalog() {
  cstab::MatrixCatalog c;
  for (const auto& p : cstab::all_problems()) c.problems.push_back(p.get());
  c.methods = cstab::all_methods();
  return c;
}

// ------------------------------------------------------------- every run ends

TEST(EveryRunEnds, TooManyFixedStepsAreRefusedUpFront) {
  Scratch s;
  const std::string out = (s.dir() / "o").string();
  for (const char* bad : {"run --problem slider-crank --method pesterev --integrator rk4 --step 1e-320 --t-end 0.1",
                          "run --problem wheel --method pesterev --integrator rk4 --step 1e-9 --t-end 1e9"}) {
    const auto start = std::chrono::steady_clock::now();
    const Outcome o = cstab_cmd(std::string(bad) + " --out " + quote(out));
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_TRUE(contains(o.out, "more than the limit of 1e+08 (--max-steps raises it)")) << o.out;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10);
    EXPECT_FALSE(fs::exists(out));
  }
  // The flag moves the limit both ways: 50 steps refused under 10, run under 100.
  Outcome o = cstab_cmd(std::string(kRun) + "--step 1e-3 --max-steps 10 --out " + quote(out));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "50 steps, more than the limit of 10")) << o.out;
  o = cstab_cmd(std::string(kRun) + "--step 1e-3 --max-steps 100 --out " + quote(out));
  EXPECT_EQ(o.code, 0) << o.out;
  o = cstab_cmd(std::string(kRun) + "--step 1e-3 --max-steps 0 --out " + quote(s.dir() / "p"));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "--max-steps: must be a number in [1, 1e15]")) << o.out;
}

TEST(EveryRunEnds, AnAdaptiveRunStopsAtItsStepLimitAsARecordedFailure) {
  Scratch s;
  const std::string out = (s.dir() / "o").string();
  const Outcome o = cstab_cmd(
      "run --problem wheel --method pesterev --integrator rk8pd --rtol 1e-8 --atol 1e-8 --t-end 1e300 "
      "--max-steps 2000 --no-series --out " + quote(out));
  ASSERT_EQ(o.code, 0) << o.out;
  const cstab::CsvTable t = cstab::read_csv(out + "/summary.csv");
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.get(0, "status"), "failed");
  EXPECT_TRUE(contains(t.get(0, "reason"), "step limit: 2000 steps taken by t = ")) << t.get(0, "reason");
  EXPECT_EQ(t.get(0, "steps"), "2000");
  EXPECT_FALSE(t.get(0, "fail_time").empty());
}

TEST(EveryRunEnds, StabilityMapsAreBoundedUpFront) {
  Scratch s;
  const std::string out = (s.dir() / "o").string();
  const std::string map =
      "stability --problem wheel --method pesterev --integrator rk4 --gain-param lambda --gains 10,100 --no-plot ";
  Outcome o = cstab_cmd(map + "--steps 1e-7 --t-end 100 --out " + quote(out));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "integration steps, more than the limit of 1e+09 (--max-steps raises it)")) << o.out;
  EXPECT_FALSE(fs::exists(out));
  o = cstab_cmd(map + "--steps 1e-3 --t-end 1 --bisect 2 --max-steps 1000 --out " + quote(out));
  EXPECT_EQ(o.code, 2) << o.out;  // 1000 steps x (2 gains + 2 bisections + 2 brackets)
  EXPECT_TRUE(contains(o.out, "about 6000 integration steps")) << o.out;
}

TEST(EveryRunEnds, MatrixCasesHaveADefaultTimeoutAndAStepLimitKey) {
  const std::string head = "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\nintegrators = \"rk4\"\n"
                           "t_end = 1\n";
  const auto plain = cstab::expand_matrix(cstab::parse_matrix(head + "step = 1e-3\n", "m.toml"), catalog());
  ASSERT_EQ(plain.cases.size(), 1u);
  EXPECT_EQ(plain.cases[0].timeout, cstab::kDefaultCaseTimeout);
  EXPECT_EQ(plain.cases[0].timeout, 600);
  // The default keeps the ids cases had before it existed ("timeout=0").
  EXPECT_TRUE(contains(plain.cases[0].config_text, "\ntimeout=0\n"));
  EXPECT_EQ(plain.cases[0].entry.id, cstab::hash_hex(plain.cases[0].config_text));
  const auto none = cstab::expand_matrix(cstab::parse_matrix(head + "step = 1e-3\ntimeout = 0\n", "m.toml"), catalog());
  EXPECT_EQ(none.cases[0].timeout, 0);
  EXPECT_NE(none.cases[0].entry.id, plain.cases[0].entry.id);
  try {
    cstab::expand_matrix(cstab::parse_matrix(head + "step = [1e-3, 1e-9]\n", "m.toml"), catalog());
    ADD_FAILURE() << "1e9 steps accepted";
  } catch (const cstab::UsageError& e) {
    EXPECT_TRUE(contains(e.what(), "m.toml:6:15: step: 1e-9 needs t_end / step = 1e+09 steps")) << e.what();
  }
  const auto raised =
      cstab::expand_matrix(cstab::parse_matrix(head + "step = 1e-9\nmax_steps = 2e9\n", "m.toml"), catalog());
  EXPECT_EQ(raised.cases[0].config.max_steps, 2e9);
  EXPECT_TRUE(contains(raised.cases[0].config_text, "max_steps=2000000000"));
}

TEST(EveryRunEnds, ATimedOutCaseIsRecordedWithoutTemporaryFiles) {
  Scratch s;
  std::ofstream(s.dir() / "m.toml") << "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\n"
                                       "integrators = \"rk4\"\nstep = 1e-6\nt_end = 50\nref_time = 0\ntimeout = 1\n";
  const fs::path out = s.dir() / "out";
  const Outcome o = cstab_cmd("matrix " + quote(s.dir() / "m.toml") + " --out " + quote(out) + " --jobs 1 --no-report");
  EXPECT_EQ(o.code, 0) << o.out;
  const cstab::CsvTable t = cstab::read_csv((out / "summary.csv").string());
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.get(0, "status"), "timeout");
  for (const auto& e : fs::recursive_directory_iterator(out))
    EXPECT_FALSE(contains(e.path().filename().string(), ".tmp.")) << e.path();
  // A timeout is a simulation outcome: cached.
  const Outcome again =
      cstab_cmd("matrix " + quote(s.dir() / "m.toml") + " --out " + quote(out) + " --jobs 1 --no-report");
  EXPECT_TRUE(contains(again.out, "1 of 1 cases cached")) << again.out;
}

// ------------------------------------------------------------- bad input

TEST(BadInput, IntegerParametersAreRangeCheckedBeforeConversion) {
  Scratch s;
  const std::string run = "run --problem wheel --method projection --integrator rk4 --step 1e-3 --t-end 0.05 ";
  for (const char* v : {"2147483648", "1e300", "2.5"}) {
    const Outcome o = cstab_cmd(run + "--param max_iter=" + v + " --out " + quote(s.dir() / "o"));
    EXPECT_EQ(o.code, 2) << v << ": " << o.out;
    EXPECT_TRUE(contains(o.out, std::string("--param max_iter=") + v + ": must be")) << o.out;
    EXPECT_FALSE(fs::exists(s.dir() / "o"));
  }
  const std::string head = "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"projection\"]\nintegrators = \"rk4\"\n"
                           "step = 1e-3\nt_end = 1\nparam.max_iter = 2147483648\n";
  try {
    cstab::expand_matrix(cstab::parse_matrix(head, "m.toml"), catalog());
    ADD_FAILURE() << "max_iter = 2^31 accepted";
  } catch (const cstab::UsageError& e) {
    EXPECT_TRUE(contains(e.what(), "m.toml:7:18: param.max_iter = 2147483648: must be <= 1e+06")) << e.what();
  }
  EXPECT_EQ(cstab_cmd(run + "--param max_iter=7 --out " + quote(s.dir() / "ok")).code, 0);
}

TEST(BadInput, CommandLineNumbersTakeNoBlanksAtEitherEnd) {
  Scratch s;
  for (const char* step : {" 1e-3", "1e-3 "}) {
    const Outcome o = cstab_cmd(std::string(kRun) + "--step '" + step + "' --out " + quote(s.dir() / "o"));
    EXPECT_EQ(o.code, 2) << "'" << step << "': " << o.out;
    EXPECT_TRUE(contains(o.out, "is not a number")) << o.out;
  }
  // Integer flags too (strtol would skip the leading blank).
  for (const char* every : {" 2", "2 ", "0x2", "2e0"}) {
    const Outcome o = cstab_cmd(std::string(kRun) + "--step 1e-3 --observe-every '" + every + "' --out " +
                                quote(s.dir() / "m"));
    EXPECT_EQ(o.code, 2) << "'" << every << "': " << o.out;
    EXPECT_TRUE(contains(o.out, "--observe-every: '" + std::string(every) + "' is not an integer")) << o.out;
    EXPECT_FALSE(fs::exists(s.dir() / "m"));
  }
  EXPECT_EQ(cstab_cmd(std::string(kRun) + "--step 1e-3 --observe-every 2 --out " + quote(s.dir() / "m")).code, 0);
}

// One number syntax everywhere (core/params.hpp: is_decimal_number): what
// strtod reads beyond decimal (hex floats, "infinity", "nan(...)") is
// refused, on the command line with exit 2 naming the flag, in files as
// "not a number".
TEST(BadInput, HexFloatsAndOtherStrtodSpellingsAreNotNumbers) {
  for (const char* text : {"1e-3", "-0.5", "2.", ".25", "1E+06", "+3"})
    EXPECT_TRUE(cstab::is_decimal_number(text)) << text;
  for (const char* text : {"0x1p-3", "0X10", "infinity", "nan(1)", "1e", "e5", ".", "-", "1.5e+", " 1", "1 ", "1,5",
                           "0x1.8p1", ""})
    EXPECT_FALSE(cstab::is_decimal_number(text)) << text;
  double v = 0;
  EXPECT_FALSE(cstab::try_parse_number("0x1p-3", v));
  EXPECT_FALSE(cstab::try_parse_number("Infinity", v));
  EXPECT_TRUE(cstab::try_parse_number(" 0.125 ", v));
  EXPECT_EQ(v, 0.125);
  EXPECT_TRUE(cstab::try_parse_number("-inf", v));  // as format_exact writes it
  EXPECT_EQ(v, -INFINITY);
  Scratch s;
  const std::string run = "run --problem wheel --method pesterev --integrator rk4 --out " + quote(s.dir() / "o") + " ";
  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"--t-end 0.05 --step 0x1p-3", "--step: '0x1p-3' is not a number"},
           {"--t-end 0x1p-1 --step 1e-3", "--t-end: '0x1p-1' is not a number"},
           {"--t-end 0.05 --step 1e-3 --param lambda=0x10", "--param lambda: '0x10' is not a number"},
           {"--t-end 0.05 --step infinity", "--step: 'infinity' is not a finite number"}}) {
    const Outcome o = cstab_cmd(run + args);
    EXPECT_EQ(o.code, 2) << args << "\n" << o.out;
    EXPECT_TRUE(contains(o.out, message)) << args << "\n" << o.out;
    EXPECT_FALSE(fs::exists(s.dir() / "o")) << args;
  }
  EXPECT_EQ(cstab_cmd(run + "--t-end 0.05 --step 0.125e-1").code, 0);
}

TEST(BadInput, NoSeriesIntoAnOldFolderLeavesNoStaleSeries) {
  Scratch s;
  const std::string out = quote(s.dir() / "o");
  ASSERT_EQ(cstab_cmd(std::string(kRun) + "--step 1e-3 --out " + out).code, 0);
  ASSERT_TRUE(fs::exists(s.dir() / "o" / "series.csv"));
  ASSERT_EQ(cstab_cmd(std::string(kRun) + "--step 1e-3 --no-series --out " + out).code, 0);
  EXPECT_FALSE(fs::exists(s.dir() / "o" / "series.csv"));
}

TEST(BadInput, ADeviceAsInputIsRefusedNotReadForever) {
  const Outcome o = cstab_cmd("matrix /dev/zero --list");
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "larger than 512 MiB")) << o.out;
}

// A finished one-case results folder, shared (read-only) by the tests below.
class Folder : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new Scratch("cstab_trust");
    std::ofstream(dir_->dir() / "m.toml")
        << "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\", \"baumgarte\"]\nintegrators = \"rk4\"\n"
           "step = [1e-2, 3e-3]\nt_end = 1\n"
           // h lambda = 15 and 4.5, beyond RK4's 2.785: pesterev diverges at both steps.
           "param.pesterev.lambda = 1500\n";
    const Outcome o = cstab_cmd("matrix " + quote(dir_->dir() / "m.toml") + " --out " + quote(shard()) +
                                " --jobs 2 --no-report");
    ASSERT_EQ(o.code, 0) << o.out;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path shard() { return dir_->dir() / "shard"; }
  // A copy of the shard to damage.
  static fs::path copy(const std::string& name) {
    const fs::path to = dir_->dir() / name;
    fs::remove_all(to);
    fs::copy(shard(), to, fs::copy_options::recursive);
    return to;
  }
  static std::string matrix_into(const fs::path& out) {
    return "matrix " + quote(dir_->dir() / "m.toml") + " --out " + quote(out) + " --jobs 2 --no-report";
  }
  static std::vector<std::string> ids() {
    std::vector<std::string> v;
    const auto t = cstab::read_csv((shard() / "cases.csv").string());
    for (size_t i = 0; i < t.rows.size(); ++i) v.push_back(t.get(i, "case_id"));
    return v;
  }
  static Scratch* dir_;
};
Scratch* Folder::dir_ = nullptr;

TEST_F(Folder, MergeRefusesCaseIdsThatAreNotSixteenHexDigits) {
  const fs::path bad = copy("bad_ids");
  std::string manifest = slurp(bad / "cases.csv");
  const std::string id = ids()[0];
  manifest.replace(manifest.find(id), id.size(), "../../escaped");
  std::ofstream(bad / "cases.csv") << manifest;
  const fs::path out = dir_->dir() / "merged";
  const Outcome o = cstab_cmd("merge " + quote(out) + " " + quote(bad));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "cases.csv:2:3: case_id: '../../escaped' is not a case id (16 hex digits)")) << o.out;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir_->dir() / "escaped"));
}

TEST_F(Folder, MalformedCasesCsvGivesFileLineColumnFromGateReportAndMerge) {
  const fs::path bad = copy("bad_manifest");
  std::string manifest = slurp(bad / "cases.csv");
  const size_t line2 = manifest.find('\n') + 1;
  manifest.replace(line2, manifest.find(',', line2) - line2, "x1");  // index = x1
  std::ofstream(bad / "cases.csv") << manifest;
  const std::string before = snapshot(bad);
  for (const std::string& cmd : {"gate --thresholds " + quote(CSTAB_SOURCE_DIR "/matrices/gate-thresholds.csv") +
                                     " " + quote(bad),
                                 "report --no-plots " + quote(bad),
                                 "merge " + quote(dir_->dir() / "m2") + " " + quote(bad)}) {
    const Outcome o = cstab_cmd(cmd);
    EXPECT_EQ(o.code, 2) << cmd << "\n" << o.out;
    EXPECT_TRUE(contains(o.out, (bad / "cases.csv").string() + ":2:1: index: 'x1' is not a count")) << o.out;
  }
  EXPECT_EQ(snapshot(bad), before);
  EXPECT_FALSE(fs::exists(dir_->dir() / "m2"));
}

TEST_F(Folder, ReportRefusesAFolderWithoutCasesAndTouchesNothing) {
  const fs::path bad = dir_->dir() / "no_cases";
  fs::create_directories(bad);
  fs::copy_file(shard() / "cases.csv", bad / "cases.csv");
  fs::copy_file(shard() / "summary.csv", bad / "summary.csv");
  const std::string before = snapshot(bad);
  const Outcome o = cstab_cmd("report --no-plots " + quote(bad));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "not a matrix results folder (no cases/ folder)")) << o.out;
  EXPECT_EQ(snapshot(bad), before);
}

TEST_F(Folder, GateUpdateNeverWritesABoundTheParserRejects) {
  const fs::path dir = copy("gate_inf");
  // A diverged case's residual (above the blow-up level 1e3) times 1e308 overflows.
  const std::string text = "problem,method,integrator,params,setting,status,max_residual\n"
                           "wheel,pesterev,rk4,lambda=1500,step=0.003,diverged,1\n";
  std::ofstream(dir / "t.csv") << text;
  const Outcome o = cstab_cmd("gate --update --factor 1e308 --thresholds " + quote(dir / "t.csv") + " " + quote(dir));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "max_residual = ")) << o.out;
  EXPECT_TRUE(contains(o.out, "x factor is not a finite number (inf)")) << o.out;
  EXPECT_EQ(slurp(dir / "t.csv"), text);
  // A factor that keeps the bound finite is written, and the parser reads it back.
  EXPECT_EQ(cstab_cmd("gate --update --factor 1e300 --thresholds " + quote(dir / "t.csv") + " " + quote(dir)).code, 0);
  EXPECT_NE(slurp(dir / "t.csv"), text);
  EXPECT_EQ(cstab_cmd("gate --thresholds " + quote(dir / "t.csv") + " " + quote(dir)).code, 0);
}

TEST_F(Folder, GateStrictFailsOnUncheckedCasesAndAddMissingAddsThem) {
  const fs::path dir = copy("gate_strict");
  ASSERT_EQ(cstab_cmd("gate --init " + quote(dir / "t.csv") + " " + quote(dir)).code, 0);
  // Drop the last row: one case is unchecked.
  std::string text = slurp(dir / "t.csv");
  text.erase(text.rfind('\n', text.size() - 2) + 1);
  std::ofstream(dir / "t.csv") << text;
  const std::string gate = "gate --thresholds " + quote(dir / "t.csv") + " ";
  EXPECT_EQ(cstab_cmd(gate + quote(dir)).code, 0);
  Outcome o = cstab_cmd(gate + "--strict " + quote(dir));
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_TRUE(contains(o.out, "--strict: 1 completed cases have no thresholds row")) << o.out;
  o = cstab_cmd(gate + "--add-missing " + quote(dir));
  EXPECT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "gate: 1 rows added")) << o.out;
  EXPECT_EQ(cstab_cmd(gate + "--strict " + quote(dir)).code, 0);
  o = cstab_cmd(gate + "--add-missing " + quote(dir));
  EXPECT_TRUE(contains(o.out, "gate: 0 rows added")) << o.out;
  // A header-only file checks nothing: an error.
  std::ofstream(dir / "empty.csv") << "problem,method,integrator,setting\n";
  o = cstab_cmd("gate --thresholds " + quote(dir / "empty.csv") + " " + quote(dir));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_TRUE(contains(o.out, "no thresholds rows")) << o.out;
}

// ------------------------------------------------------------- the lock

TEST_F(Folder, AFolderInUseIsRefusedNamingItsHolderAndAStaleLockIsTakenOver) {
  const fs::path dir = copy("locked");
  {
    const cstab::FolderLock held(dir.string(), "the test");
    const std::string before = snapshot(dir);
    const std::string holder = "in use by another cstab command (pid " + std::to_string(::getpid()) + " the test)";
    for (const std::string& cmd :
         {matrix_into(dir), "report --no-plots " + quote(dir), "merge " + quote(dir) + " " + quote(shard()),
          "gate --update --thresholds " + quote(dir / "t.csv") + " " + quote(dir)}) {
      if (cmd.rfind("gate", 0) == 0) std::ofstream(dir / "t.csv") << "problem,method,integrator,setting\nwheel,pesterev,rk4,step=0.01\n";
      const std::string snap = snapshot(dir);
      const Outcome o = cstab_cmd(cmd);
      EXPECT_EQ(o.code, 2) << cmd << "\n" << o.out;
      EXPECT_TRUE(contains(o.out, holder)) << cmd << "\n" << o.out;
      EXPECT_EQ(snapshot(dir), snap) << cmd;
    }
    (void)before;
  }
  // The holder is gone (its lock file remains, naming a dead pid): taken over.
  std::ofstream(dir / cstab::FolderLock::file_name()) << "999999999\ncstab matrix\n";
  const Outcome o = cstab_cmd(matrix_into(dir));
  EXPECT_EQ(o.code, 0) << o.out;
  EXPECT_EQ(std::stol(slurp(dir / cstab::FolderLock::file_name())) > 0, true);
}

// A refused `gate --update` (the folder is locked, then the input found
// bad) leaves no lock file where there was none; one that succeeds keeps
// it, naming the last holder.
TEST_F(Folder, ARefusedGateUpdateLeavesNoNewLockFile) {
  const fs::path dir = copy("gate_refused");
  fs::remove(dir / cstab::FolderLock::file_name());
  const std::string row = "problem,method,integrator,params,setting,status,max_residual\n"
                          "wheel,pesterev,rk4,lambda=1500,step=0.003,ok,1\n";
  std::ofstream(dir / "t.csv") << row;
  const std::string before = snapshot(dir);
  for (const std::string& bad : std::vector<std::string>{
           "--update --csv " + quote(dir / "c.csv"),  // flags that do not go together
           "--update --strict",                       // idem
           "--update --factor 1e308"}) {              // a bound that would overflow
    const Outcome o = cstab_cmd("gate " + bad + " --thresholds " + quote(dir / "t.csv") + " " + quote(dir));
    EXPECT_EQ(o.code, 2) << bad << "\n" << o.out;
    EXPECT_FALSE(fs::exists(dir / cstab::FolderLock::file_name())) << bad << "\n" << o.out;
    EXPECT_EQ(snapshot(dir), before) << bad;
  }
  const Outcome o = cstab_cmd("gate --update --thresholds " + quote(dir / "t.csv") + " " + quote(dir));
  EXPECT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(fs::exists(dir / cstab::FolderLock::file_name()));
  // An existing lock file stays, refused command or not.
  const Outcome refused = cstab_cmd("gate --update --strict --thresholds " + quote(dir / "t.csv") + " " + quote(dir));
  EXPECT_EQ(refused.code, 2) << refused.out;
  EXPECT_TRUE(fs::exists(dir / cstab::FolderLock::file_name()));
}

// `merge` reads no shard a matrix is still writing: refused at once naming
// the holder, nothing written; free again, the same merge succeeds.
TEST_F(Folder, MergeRefusesAShardLockedByARunningMatrix) {
  const fs::path busy = copy("busy_shard");
  const fs::path out = dir_->dir() / "merged_busy";
  {
    const cstab::FolderLock held(busy.string(), "cstab matrix");
    const std::string before = snapshot(busy);
    const Outcome o = cstab_cmd("merge --no-report " + quote(out) + " " + quote(busy));
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_TRUE(contains(o.out, busy.string() + ": in use by another cstab command (pid " +
                                    std::to_string(::getpid()) + " cstab matrix)"))
        << o.out;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(snapshot(busy), before);
  }
  // A shard with no lock file at all (never locked) is read as before.
  const fs::path plain = copy("plain_shard");
  fs::remove(plain / cstab::FolderLock::file_name());
  const Outcome o = cstab_cmd("merge --no-report " + quote(out) + " " + quote(busy));
  EXPECT_EQ(o.code, 0) << o.out;
  EXPECT_EQ(cstab::testing::summary_without_timing(out / "summary.csv"),
            cstab::testing::summary_without_timing(shard() / "summary.csv"));
  const Outcome o2 = cstab_cmd("merge --no-report " + quote(dir_->dir() / "merged_plain") + " " + quote(plain));
  EXPECT_EQ(o2.code, 0) << o2.out;
  EXPECT_FALSE(fs::exists(plain / cstab::FolderLock::file_name()));
  // While merge holds its reading lock, a matrix on the shard is refused:
  // the same kernel lock, seen from the other side.
  {
    const cstab::FolderLock reading(busy.string(), "cstab merge", cstab::FolderLock::Mode::kRead);
    const Outcome m = cstab_cmd(matrix_into(busy));
    EXPECT_EQ(m.code, 2) << m.out;
    EXPECT_TRUE(contains(m.out, "in use by another cstab command")) << m.out;
  }
}

// ------------------------------------------------------------- the cache verifies

TEST_F(Folder, ACachedCaseWhoseFilesChangedIsRerunSayingWhy) {
  const fs::path dir = copy("verify");
  const auto id = ids();
  ASSERT_EQ(id.size(), 4u);
  const std::string full = cstab::testing::summary_without_timing(shard() / "summary.csv");
  // Untouched: all cached.
  Outcome o = cstab_cmd(matrix_into(dir));
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "4 of 4 cases cached")) << o.out;
  // Truncated series, an edited number in a record's summary rows, a
  // deleted series, a record copied over another case's.
  const fs::path c0 = dir / "cases" / id[0], c1 = dir / "cases" / id[1], c2 = dir / "cases" / id[2],
                 c3 = dir / "cases" / id[3];
  fs::resize_file(c0 / "series.csv.gz", fs::file_size(c0 / "series.csv.gz") / 2);
  std::string record = slurp(c1 / "case.txt");
  record[record.size() - 2] = record[record.size() - 2] == '1' ? '2' : '1';
  std::ofstream(c1 / "case.txt", std::ios::binary) << record;
  fs::remove(c2 / "series.csv.gz");
  fs::copy_file(c2 / "case.txt", c3 / "case.txt", fs::copy_options::overwrite_existing);
  o = cstab_cmd(matrix_into(dir));
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "rerun ")) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[0] + "): series.csv.gz has ")) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[1] + "): case.txt: its summary rows differ from the recorded hash (edited)"))
      << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[2] + "): series.csv.gz missing")) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[3] + "): case.txt records another configuration (swapped or copied")) << o.out;
  EXPECT_TRUE(contains(o.out, "4 run, 0 cached")) << o.out;
  EXPECT_EQ(cstab::testing::summary_without_timing(dir / "summary.csv"), full);
  // And now all of it verifies again.
  o = cstab_cmd(matrix_into(dir));
  EXPECT_TRUE(contains(o.out, "4 of 4 cases cached")) << o.out;
  // A truncated record, a stray summary.csv beside a record, a deleted
  // record, and a folder as an older cstab wrote it (key.txt and
  // summary.csv, no case.txt).
  fs::resize_file(c0 / "case.txt", fs::file_size(c0 / "case.txt") - 10);
  std::ofstream(c1 / "summary.csv") << "case_id,repeat\n" << id[1] << ",0\n";
  fs::remove(c2 / "case.txt");
  fs::rename(c3 / "case.txt", c3 / "key.txt");
  std::ofstream(c3 / "summary.csv") << "case_id,repeat\n" << id[3] << ",0\n";
  o = cstab_cmd(matrix_into(dir));
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[0] + "): case.txt: its summary rows have ")) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[1] + "): summary.csv not recorded in case.txt")) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[2] + "): no case.txt (unfinished)")) << o.out;
  EXPECT_TRUE(contains(o.out, "(" + id[3] + "): written by an older cstab")) << o.out;
  EXPECT_TRUE(contains(o.out, "4 run, 0 cached")) << o.out;
  EXPECT_EQ(cstab::testing::summary_without_timing(dir / "summary.csv"), full);
  for (const auto& i : id) {  // a case folder: its record and its series, nothing else
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir / "cases" / i)) names.insert(e.path().filename().string());
    EXPECT_EQ(names, (std::set<std::string>{"case.txt", "series.csv.gz"})) << i;
  }
}

// ------------------------------------------------------------- series the pictures read

size_t series_files(const fs::path& dir) {
  size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "cases"))
    if (e.path().filename() == "series.csv.gz") ++n;
  return n;
}

TEST_F(Folder, TheMatrixKeepsOnlyWhatThePicturesReadAndKeepSeriesBringsTheWholeSeriesBack) {
  const fs::path dir = copy("series_kept");
  const auto id = ids();
  ASSERT_EQ(id.size(), 4u);
  ASSERT_EQ(series_files(dir), 4u);
  const std::string full = cstab::testing::summary_without_timing(shard() / "summary.csv");
  const std::string with_report = "matrix " + quote(dir_->dir() / "m.toml") + " --out " + quote(dir) + " --jobs 2";
  // With the report: pesterev diverges at both steps and none of its runs
  // is marked for the overlays, so no picture reads its series; of
  // baumgarte's two runs, the pictures read the more accurate. The other
  // three series go; the one kept is cut to the columns the pictures read,
  // at plot precision.
  Outcome o = cstab_cmd(with_report);
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "4 of 4 cases cached")) << o.out;
  EXPECT_TRUE(contains(o.out, "dropped 3 others")) << o.out;
  EXPECT_TRUE(contains(o.out, "cut the 1 series the pictures read to their columns and 7 digits")) << o.out;
  EXPECT_EQ(series_files(dir), 1u);
  size_t dropped = 0;
  for (const auto& i : id) {
    const std::string record = slurp(dir / "cases" / i / "case.txt");
    const fs::path series = dir / "cases" / i / "series.csv.gz";
    const bool has = fs::exists(series);
    EXPECT_EQ(contains(record, "\nfile series.csv.gz "), has) << record;
    EXPECT_EQ(contains(record, "\ndropped series.csv.gz\n"), !has) << record;
    EXPECT_EQ(contains(record, "\nfor-pictures series.csv.gz\n"), has) << record;
    dropped += !has;
    if (!has) continue;
    // The kept one: t, the positions the trajectories show, the residuals
    // and the energy drift the overlay shows; the whole series' numbers at
    // 7 digits.
    const std::string whole = cstab::gzip_decompress(slurp(shard() / "cases" / i / "series.csv.gz"), 1 << 26);
    const std::string cut = cstab::gzip_decompress(slurp(series), 1 << 26);
    EXPECT_EQ(cut.substr(0, cut.find('\n')), "t,x,z,theta,phi,alpha,residual_distance,residual_rolling,energy_drift");
    const std::set<std::string> read = {"x", "z", "theta", "phi", "alpha", "residual_distance", "residual_rolling",
                                        "energy_drift"};
    EXPECT_TRUE(cut == cstab::csv_at_plot_precision(cstab::csv_select_columns(whole, read)));
    EXPECT_LT(fs::file_size(series), fs::file_size(shard() / "cases" / i / "series.csv.gz") / 2);
  }
  EXPECT_EQ(dropped, 3u);
  // The report rebuilt from the folder picks the same runs and draws the
  // same pictures from the rounded series: the same data, nothing redrawn.
  auto plot_data = [&](const std::string& name) {
    return cstab::gzip_decompress(slurp(dir / "plots" / "data" / (name + ".dat.gz")), 1 << 26);
  };
  const std::string trajectory = plot_data("wheel_trajectory"), overlay = plot_data("wheel_overlay");
  ASSERT_FALSE(trajectory.empty());
  ASSERT_FALSE(overlay.empty());
  o = cstab_cmd("report " + quote(dir));
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_EQ(plot_data("wheel_trajectory"), trajectory);
  EXPECT_EQ(plot_data("wheel_overlay"), overlay);
  EXPECT_TRUE(contains(o.out, "(0 plots drawn, ")) << o.out;
  // Dropped and cut series are still cached results, and nothing more goes
  // or is cut again.
  o = cstab_cmd(with_report);
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "4 of 4 cases cached")) << o.out;
  EXPECT_FALSE(contains(o.out, "dropped")) << o.out;
  EXPECT_FALSE(contains(o.out, "cut the")) << o.out;
  // --keep-series reruns exactly the cases whose series went or were cut.
  o = cstab_cmd(with_report + " --keep-series");
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_TRUE(contains(o.out, "its series was dropped by an earlier run")) << o.out;
  EXPECT_TRUE(contains(o.out, "its series was cut to the pictures' columns and 7 digits by an earlier run")) << o.out;
  EXPECT_TRUE(contains(o.out, "4 run, 0 cached")) << o.out;
  EXPECT_EQ(series_files(dir), 4u);
  for (const auto& i : id)
    EXPECT_EQ(slurp(dir / "cases" / i / "series.csv.gz"), slurp(shard() / "cases" / i / "series.csv.gz")) << i;
  EXPECT_EQ(cstab::testing::summary_without_timing(dir / "summary.csv"), full);
}

TEST_F(Folder, ACaseRecordHoldsTheKeyTheSeriesHashAndTheSummaryRows) {
  const fs::path folder = shard() / "cases" / ids()[0];
  const std::string text = slurp(folder / "case.txt");
  EXPECT_TRUE(contains(text, "\nfile series.csv.gz ")) << text;
  EXPECT_TRUE(contains(text, "binary=")) << text;
  // The matrix keeps the series compressed only, and the summary rows in the record.
  EXPECT_FALSE(fs::exists(folder / "series.csv"));
  EXPECT_FALSE(fs::exists(folder / "summary.csv"));
  EXPECT_FALSE(fs::exists(folder / "key.txt"));
  std::string why;
  const auto record = cstab::parse_case_record(text, why);
  ASSERT_TRUE(record) << why;
  EXPECT_TRUE(contains(text, record->head + "summary " + std::to_string(record->summary.size()) + " ")) << text;
  const cstab::CsvTable rows = cstab::parse_csv(record->summary, "case.txt");
  ASSERT_EQ(rows.rows.size(), 1u);
  EXPECT_EQ(rows.get(0, "case_id"), ids()[0]);
  // The folder's summary.csv holds the same row (with the sweep).
  const cstab::CsvTable all = cstab::read_csv((shard() / "summary.csv").string());
  EXPECT_EQ(all.get(0, "case_id"), ids()[0]);
  for (const char* column : {"status", "steps", "max_residual"}) {
    EXPECT_FALSE(rows.get(0, column).empty()) << column;
    EXPECT_EQ(all.get(0, column), rows.get(0, column)) << column;
  }
  // Any byte less, or one more, and the record is not whole.
  EXPECT_FALSE(cstab::parse_case_record(text.substr(0, text.size() - 1), why));
  EXPECT_TRUE(contains(why, "recorded (truncated or edited)")) << why;
  EXPECT_FALSE(cstab::parse_case_record(text + "\n", why));
  EXPECT_FALSE(cstab::parse_case_record(text.substr(0, text.find("\nsummary ") + 1), why));
  EXPECT_TRUE(contains(why, "no summary line")) << why;
}

// ------------------------------------------------------------- the binary's identity

// A copy of the cstab binary, execute-only (mode 0111).
fs::path execute_only_copy(const Scratch& s) {
  const fs::path copy = s.dir() / "cstab-x";
  fs::copy_file(CSTAB_BINARY, copy);
  fs::permissions(copy, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec);
  return copy;
}

TEST(BinaryIdentity, IsTheSizeAndHashOfTheFileAndUnknownIfItCannotBeRead) {
  Scratch s;
  const std::string bytes = slurp(CSTAB_BINARY);
  EXPECT_EQ(cstab::binary_identity_of(CSTAB_BINARY), std::to_string(bytes.size()) + "-" + cstab::hash_hex(bytes));
  // Deleted (or replaced) while it starts: /proc/self/exe names a file
  // that is gone ("PATH (deleted)"); a folder; an execute-only copy (root
  // reads it anyway).
  EXPECT_EQ(cstab::binary_identity_of((s.dir() / "cstab (deleted)").string()), "unknown");
  EXPECT_EQ(cstab::binary_identity_of(s.dir().string()), "unknown");
  if (::geteuid() != 0) {
    EXPECT_EQ(cstab::binary_identity_of(execute_only_copy(s).string()), "unknown");
  }
}

// Issue 16: "if it cannot be read, nothing is cached": a matrix run with
// the identity "unknown" runs every case again, the second time too.
TEST(BinaryIdentity, AnUnreadableBinaryReusesNothing) {
  Scratch s;
  const std::string text =
      "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\nintegrators = \"rk4\"\n"
      "step = [1e-2, 5e-3]\nt_end = 0.2\n";
  const cstab::Expansion ex = cstab::expand_matrix(cstab::parse_matrix(text, "m.toml"), catalog());
  ASSERT_EQ(ex.cases.size(), 2u);
  cstab::MatrixRunOptions opt;
  opt.out_dir = (s.dir() / "out").string();
  opt.jobs = 1;
  opt.matrix_text = text;
  opt.selected_cases = ex.cases.size();
  opt.find_problem = [](const std::string& name) -> const cstab::Problem& { return cstab::find_problem(name); };
  opt.binary_id = cstab::binary_identity_of((s.dir() / "cstab (deleted)").string());
  ASSERT_EQ(opt.binary_id, "unknown");
  std::ostringstream log;
  for (int round = 0; round < 2; ++round) {
    const cstab::MatrixRunStats stats = cstab::run_matrix(ex.cases, opt, log, false);
    EXPECT_EQ(stats.run, 2u) << log.str();
    EXPECT_EQ(stats.cached, 0u) << log.str();
  }
  // A readable binary does not reuse what "unknown" wrote either.
  opt.binary_id = cstab::binary_identity_of(CSTAB_BINARY);
  EXPECT_EQ(cstab::run_matrix(ex.cases, opt, log, false).cached, 0u) << log.str();
  EXPECT_EQ(cstab::run_matrix(ex.cases, opt, log, false).cached, 2u) << log.str();
}

// The same end to end: an execute-only copy of cstab (it runs, but cannot
// read itself) says so and reruns every case. Root reads any file, so
// there the test above (the identity given to the matrix) stands for it.
// As root (CI, containers) an execute-only file is still readable, so the
// runs go through `setpriv` as the unprivileged uid 65534 (util-linux, on
// every Debian), in a scratch folder it may write to.
TEST(BinaryIdentity, AnExecuteOnlyCstabSaysItCachesNothingAndRerunsEveryCase) {
  Scratch s;
  const fs::path cstab = execute_only_copy(s);
  std::ofstream(s.dir() / "m.toml") << "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\n"
                                       "integrators = \"rk4\"\nstep = [1e-2, 5e-3]\nt_end = 0.2\n";
  std::string as_user;
  if (::geteuid() == 0) {
    fs::permissions(s.dir(), fs::perms::all);
    fs::permissions(s.dir() / "m.toml", fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                                             fs::perms::others_read);
    as_user = "setpriv --reuid=65534 --regid=65534 --clear-groups ";
    // The unprivileged user cannot read the copy: the premise of the test.
    const Outcome premise = cstab::testing::run_shell(as_user + "cat " + quote(cstab) + " > /dev/null");
    ASSERT_NE(premise.code, 0) << "uid 65534 can read the execute-only copy: " << premise.out;
  }
  const std::string cmd = as_user + quote(cstab) + " matrix " + quote(s.dir() / "m.toml") + " --out " +
                          quote(s.dir() / "out") + " --no-report";
  for (int round = 0; round < 2; ++round) {
    const Outcome o = cstab::testing::run_shell(cmd);
    ASSERT_EQ(o.code, 0) << o.out;
    EXPECT_TRUE(contains(o.out, "the cstab binary cannot be read, so no result is reused")) << o.out;
    EXPECT_TRUE(contains(o.out, "2 run, 0 cached")) << o.out;
  }
}

}  // namespace

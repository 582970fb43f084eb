// The cstab binary as a user sees it: bad input gives exit code 2, a
// one-line message naming the bad flag, and no output files; a good run
// writes summary.csv and series.csv with the documented columns.
#include <gtest/gtest.h>

#include "cli/args.hpp"
#include "core/problem.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cctype>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cstab::testing::exit_code;
using cstab::testing::quote;
using cstab::testing::slurp;
using cstab::find_problem;
using cstab::Problem;

// A scratch folder per test, removed afterwards.
struct Scratch : cstab::testing::Scratch {
  Scratch() : cstab::testing::Scratch("cstab_cli") {}
};

struct Outcome {
  int code = -1;
  std::string out, err;
};

Outcome run_cli(const std::vector<std::string>& args, const fs::path& scratch) {
  std::string cmd = quote(CSTAB_BINARY);
  // (appended piecewise: `" " + std::string&&` trips GCC 12's -Wrestrict false positive)
  for (const auto& a : args) {
    cmd += ' ';
    cmd += quote(a);
  }
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  cmd += " >";
  cmd += quote(out.string());
  cmd += " 2>";
  cmd += quote(err.string());
  const int status = std::system(cmd.c_str());
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = slurp(out);
  o.err = slurp(err);
  return o;
}

// Output files or temporaries anywhere below `dir`.
std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> found;
  std::error_code ec;
  if (!fs::exists(dir, ec) || !fs::is_directory(dir, ec)) return found;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name == "summary.csv" || name == "series.csv" || name.find(".tmp.") != std::string::npos)
      found.push_back(e.path().string());
  }
  return found;
}

std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int col(const std::string& name) const {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    return -1;
  }
};

// Plain CSV (the harness quotes only fields with commas; the series has none).
Csv read_csv(const fs::path& p) {
  Csv c;
  std::ifstream in(p);
  std::string line;
  if (std::getline(in, line)) c.header = split(line);
  while (std::getline(in, line))
    if (!line.empty()) c.rows.push_back(split(line));
  return c;
}

double num(const std::string& s) { return s.empty() ? std::nan("") : std::strtod(s.c_str(), nullptr); }

// ---------------------------------------------------------------------------

struct BadCase {
  std::string label;
  std::vector<std::string> args;  // everything but --out
  std::string names;              // the message must contain this
};

const std::vector<std::string> kGood = {"run", "--problem", "wheel", "--method", "pesterev", "--integrator", "rk4",
                                        "--step", "1e-3", "--t-end", "0.05"};

std::vector<std::string> with(std::vector<std::string> base, const std::string& flag, const std::string& value) {
  for (size_t i = 0; i + 1 < base.size(); ++i)
    if (base[i] == flag) {
      base[i + 1] = value;
      return base;
    }
  base.push_back(flag);
  base.push_back(value);
  return base;
}
std::vector<std::string> without(std::vector<std::string> base, const std::string& flag) {
  for (size_t i = 0; i + 1 < base.size(); ++i)
    if (base[i] == flag) {
      base.erase(base.begin() + long(i), base.begin() + long(i) + 2);
      break;
    }
  return base;
}

std::vector<BadCase> bad_cases() {
  std::vector<std::string> adaptive = with(without(kGood, "--step"), "--integrator", "rk8pd");
  adaptive = with(with(adaptive, "--rtol", "1e-6"), "--atol", "1e-6");
  return {
      {"unknown_problem", with(kGood, "--problem", "no-such-problem"), "--problem"},
      {"unknown_method", with(kGood, "--method", "no-such-method"), "--method"},
      {"unknown_integrator", with(kGood, "--integrator", "no-such-integrator"), "--integrator"},
      {"unknown_param", with(kGood, "--param", "no_such_param=1"), "--param no_such_param"},
      {"param_without_value", with(kGood, "--param", "lambda"), "--param"},
      {"problem_param_unknown", with(kGood, "--problem-param", "N=3"),
       "--problem-param N: unknown parameter for problem 'wheel' (known: none)"},
      {"problem_param_out_of_range", with(with(kGood, "--problem", "pendulum"), "--problem-param", "length=0"),
       "--problem-param length=0: must be in [0.01, 100]"},
      {"problem_param_nan", with(with(kGood, "--problem", "pendulum"), "--problem-param", "angle=nan"),
       "--problem-param angle: 'nan' is not a finite number (angle must be in [-179, 179])"},
      {"problem_param_word", with(with(kGood, "--problem", "pendulum"), "--problem-param", "length=long"),
       "--problem-param length: 'long' is not a number (length must be in [0.01, 100])"},
      {"problem_param_without_value", with(kGood, "--problem-param", "length"), "--problem-param length: expected"},
      {"step_zero", with(kGood, "--step", "0"), "--step"},
      {"step_negative", with(kGood, "--step", "-1"), "--step"},
      {"step_nan", with(kGood, "--step", "nan"), "--step"},
      {"step_inf", with(kGood, "--step", "inf"), "--step"},
      {"step_garbage", with(kGood, "--step", "1e-3x"), "--step"},
      {"t_end_zero", with(kGood, "--t-end", "0"), "--t-end"},
      {"t_end_nan", with(kGood, "--t-end", "nan"), "--t-end"},
      {"t_end_negative", with(kGood, "--t-end", "-2"), "--t-end"},
      {"lambda_negative", with(kGood, "--param", "lambda=-5"), "--param lambda"},
      {"lambda_zero", with(kGood, "--param", "lambda=0"), "--param lambda"},
      {"lambda_nan", with(kGood, "--param", "lambda=nan"), "--param lambda"},
      {"missing_step_for_rk4", without(kGood, "--step"), "--step"},
      {"step_for_rk8pd", with(adaptive, "--step", "1e-3"), "--step"},
      {"missing_rtol_for_rk8pd", without(adaptive, "--rtol"), "--rtol"},
      {"rtol_nan", with(adaptive, "--rtol", "nan"), "--rtol"},
      {"param_for_minimal", with(with(kGood, "--method", "minimal"), "--param", "lambda=3"), "--param lambda"},
      {"times_beyond_t_end", with(kGood, "--times", "0.5"), "--times"},
      {"times_negative", with(kGood, "--times", "-0.01"), "--times"},
      {"unknown_option", with(kGood, "--no-such-option", "1"), "--no-such-option"},
      {"missing_problem", without(kGood, "--problem"), "--problem"},
      // issue 9 audit
      {"unknown_formulation", with(kGood, "--formulation", "lagrange"), "--formulation"},
      {"formulation_of_another_method", with(with(kGood, "--method", "baumgarte"), "--formulation", "state-space"),
       "--formulation"},
      {"dae_method_with_rk4", with(kGood, "--method", "ida-ggl"), "--integrator"},
      {"ode_method_with_ida", with(adaptive, "--integrator", "ida"), "--integrator"},
      {"minimal_on_biped", with(with(kGood, "--problem", "biped"), "--method", "minimal"), "--method"},
      {"step_larger_than_t_end", with(kGood, "--step", "1"), "--step"},
      {"t_end_overflow", with(kGood, "--t-end", "1e999"), "--t-end"},
      {"atol_negative", with(adaptive, "--atol", "-1e-6"), "--atol"},
      {"tol_for_rk4", with(with(kGood, "--rtol", "1e-6"), "--atol", "1e-6"), "--rtol"},
      {"step_given_twice", [] { auto a = kGood; a.insert(a.end(), {"--step", "1e-3"}); return a; }(), "--step"},
      {"param_given_twice",
       [] { auto a = kGood; a.insert(a.end(), {"--param", "lambda=1", "--param", "lambda=2"}); return a; }(),
       "--param lambda"},
      {"ref_time_negative", with(kGood, "--ref-time", "-2"), "--ref-time"},
      {"ref_time_beyond_t_end", with(kGood, "--ref-time", "3"), "--ref-time"},
      {"observe_every_zero", with(kGood, "--observe-every", "0"), "--observe-every"},
      {"observe_every_overflows_int", with(kGood, "--observe-every", "99999999999999"), "--observe-every"},
      {"observe_every_fraction", with(kGood, "--observe-every", "1.5"), "--observe-every"},
      {"blowup_zero", with(kGood, "--blowup", "0"), "--blowup"},
      {"sample_every_negative", with(kGood, "--sample-every", "-1"), "--sample-every"},
      {"switch_with_value", with(kGood, "--no-series=1", "x"), "--no-series"},
      {"positional_argument", [] { auto a = kGood; a.push_back("extra"); return a; }(), "extra"},
      // the CLI11 parser: its errors in our words, naming the option
      {"t_end_word", with(kGood, "--t-end", "reference"), "--t-end"},
      {"t_end_ref_trailing", with(kGood, "--t-end", "ref "), "--t-end"},
      {"value_missing_before_option", [] { auto a = kGood; a.push_back("--blowup"); return a; }(), "--blowup"},
      {"value_missing_before_help", [] { auto a = kGood; a.insert(a.end(), {"--formulation", "--help"}); return a; }(),
       "--formulation: missing value"},
      {"inline_empty_value", [] { auto a = kGood; a.push_back("--blowup="); return a; }(), "--blowup: missing value"},
      {"unknown_inline_option", [] { auto a = kGood; a.push_back("--no-such=3"); return a; }(),
       "--no-such: unknown option"},
      {"unknown_short_option", [] { auto a = kGood; a.push_back("-x"); return a; }(), "-x: unknown option"},
      {"formulation_given_twice",
       [] { auto a = kGood; a.insert(a.end(), {"--formulation", "state-space", "--formulation", "x"}); return a; }(),
       "--formulation: given more than once"},
      {"perturb_nan", with(kGood, "--perturb", "nan"), "--perturb"},
      {"perturb_negative", with(kGood, "--perturb", "-1e-3"), "--perturb"},
      {"recovery_threshold_garbage", with(kGood, "--recovery-threshold", "1e-10x"), "--recovery-threshold"},
      {"recovery_threshold_zero", with(kGood, "--recovery-threshold", "0"), "--recovery-threshold"},
      {"drift_fit_from_inf", with(kGood, "--drift-fit-from", "inf"), "--drift-fit-from"},
      {"drift_fit_from_negative", with(kGood, "--drift-fit-from", "-1"), "--drift-fit-from"},
      {"sample_every_nan", with(kGood, "--sample-every", "nan"), "--sample-every"},
      {"observe_every_garbage", with(kGood, "--observe-every", "2x"), "--observe-every"},
      {"blowup_trailing_garbage", with(kGood, "--blowup", "1e3 "), "--blowup"},
      {"missing_t_end", without(kGood, "--t-end"), "--t-end: required"},
  };
}

// The other commands. `{out}` is replaced by a fresh folder below the
// scratch folder; `{shard}` by a finished one-case matrix folder.
struct OtherBadCase {
  std::string label;
  std::vector<std::string> args;
  std::string names;
};

std::vector<OtherBadCase> other_bad_cases() {
  const std::vector<std::string> stab = {"stability", "--problem", "wheel", "--method", "pesterev", "--integrator",
                                         "rk4", "--gain-param", "lambda", "--steps", "1e-3", "--gains", "10",
                                         "--t-end", "0.05", "--no-plot", "--out", "{out}"};
  return {
      {"stability_adaptive_integrator", with(stab, "--integrator", "rk8pd"), "--integrator"},
      {"stability_steps_zero", with(stab, "--steps", "0"), "--steps"},
      {"stability_gains_missing", without(stab, "--gains"), "--gains"},
      {"stability_gains_negative", with(stab, "--gains", "10,-10"), "--gains"},
      {"stability_gain_param_unknown", with(stab, "--gain-param", "foo"), "--gain-param foo"},
      // A parameter swept outside its own range: HHT's alpha is in [-1/3, 0].
      {"stability_gains_out_of_range",
       with(with(with(with(stab, "--method", "hht"), "--integrator", "own"), "--gain-param", "alpha"), "--gains",
            "-0.1,0.5"),
       "--gains: 0.5: alpha must be in"},
      {"stability_perturb_negative", [&] { auto a = stab; a.insert(a.end() - 2, {"--perturb", "-1"}); return a; }(),
       "--perturb"},
      {"stability_gain_param_also_given", with(stab, "--param", "lambda=5"), "--gain-param"},
      {"stability_bisect_negative", with(stab, "--bisect", "-1"), "--bisect"},
      {"stability_bisect_huge", with(stab, "--bisect", "100000000000"), "--bisect"},  // was a hang
      {"stability_t_end_nan", with(stab, "--t-end", "nan"), "--t-end"},
      {"stability_t_end_word", with(stab, "--t-end", "reference"), "--t-end"},
      {"stability_bisect_fraction", with(stab, "--bisect", "2.5"), "--bisect"},
      {"stability_blowup_nan", with(stab, "--blowup", "nan"), "--blowup"},
      {"stability_no_plot_with_value", [&] { auto a = stab; a.push_back("--no-plot=yes"); return a; }(),
       "--no-plot: takes no value"},
      {"stability_unknown_option", with(stab, "--step", "1e-3"), "--step: unknown option"},
      {"stability_missing_out", without(stab, "--out"), "--out: required"},
      {"matrix_missing_file", {"matrix", "/nonexistent/m.toml", "--out", "{out}"}, "/nonexistent/m.toml"},
      {"matrix_folder_as_file", {"matrix", "/tmp", "--out", "{out}"}, "/tmp: is a folder"},
      {"matrix_jobs_zero", {"matrix", "--jobs", "0", "--out", "{out}"}, "--jobs"},
      {"matrix_jobs_garbage", {"matrix", "--jobs", "x", "--out", "{out}"}, "--jobs"},
      {"matrix_shard_out_of_range", {"matrix", "--shard", "3/2", "--out", "{out}"}, "--shard"},
      {"matrix_filter_matches_nothing", {"matrix", "--filter", "no-such-case", "--out", "{out}"}, "--filter"},
      {"matrix_two_files", {"matrix", "a.toml", "b.toml", "--out", "{out}"}, "b.toml"},
      {"merge_one_argument", {"merge", "{out}"}, "usage"},
      {"merge_not_a_results_folder", {"merge", "{out}", "/tmp"}, "/tmp"},
      {"merge_jobs_zero", {"merge", "{out}", "{shard}", "--jobs", "0"}, "--jobs"},  // used to write first
      {"report_not_a_results_folder", {"report", "/tmp"}, "/tmp"},
      {"report_jobs_zero", {"report", "{shard}", "--jobs", "0"}, "--jobs"},
      {"matrix_jobs_negative", {"matrix", "--jobs", "-2", "--out", "{out}"}, "--jobs"},
      {"matrix_unknown_option", {"matrix", "--jbos", "2", "--out", "{out}"}, "--jbos: unknown option"},
      {"matrix_out_missing_value", {"matrix", "--out"}, "--out: missing value"},
      {"merge_no_report_with_value", {"merge", "{out}", "{shard}", "--no-report=1"}, "--no-report: takes no value"},
      {"report_no_folder", {"report"}, "DIR: required"},
      {"report_two_folders", {"report", "{shard}", "{shard}"}, "unexpected argument"},
      {"gate_no_folder", {"gate"}, "DIR: required"},
      {"gate_update_with_value", {"gate", "--update=yes", "{shard}"}, "--update: takes no value"},
      {"gate_factor_garbage", {"gate", "--update", "--factor", "10x", "{shard}"}, "--factor"},
      {"gate_time_factor_nan", {"gate", "--update", "--time-factor", "nan", "{shard}"}, "--time-factor"},
      {"list_extra_argument", {"list", "extra"}, "extra"},
      {"list_unknown_option", {"list", "--all"}, "--all: unknown option"},
      {"unknown_command", {"frobnicate"}, "frobnicate"},
      {"help_unknown_command", {"help", "frobnicate"}, "frobnicate"},
      {"unknown_top_level_option", {"--verbose"}, "--verbose: unknown option"},
  };
}

class OtherBadInput : public ::testing::TestWithParam<OtherBadCase> {};

TEST_P(OtherBadInput, ExitsTwoWithOneLineNamingTheInputAndWritesNothing) {
  const OtherBadCase& c = GetParam();
  Scratch s;
  const fs::path out = s.dir() / "out", shard = s.dir() / "shard";
  bool needs_shard = false;
  auto args = c.args;
  for (auto& a : args) {
    if (a == "{out}") a = out.string();
    if (a == "{shard}") a = shard.string(), needs_shard = true;
  }
  if (needs_shard) {
    std::ofstream(s.dir() / "one.toml") << "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\n"
                                           "integrators = \"rk4\"\nstep = 1e-3\nt_end = 0.01\n";
    ASSERT_EQ(run_cli({"matrix", (s.dir() / "one.toml").string(), "--out", shard.string(), "--no-report"}, s.dir()).code,
              0);
  }
  const auto shard_files = [&] {
    std::vector<std::string> files;
    if (fs::exists(shard))
      for (const auto& e : fs::recursive_directory_iterator(shard)) files.push_back(e.path().string() + slurp(e.path()));
    std::sort(files.begin(), files.end());
    return files;
  };
  const auto before = shard_files();
  const Outcome o = run_cli(args, s.dir());
  EXPECT_EQ(o.code, 2) << "stderr: " << o.err;
  ASSERT_FALSE(o.err.empty());
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << "not one line: " << o.err;
  EXPECT_NE(o.err.find(c.names), std::string::npos) << "message does not name '" << c.names << "': " << o.err;
  EXPECT_FALSE(fs::exists(out)) << "output folder created";
  EXPECT_EQ(shard_files(), before) << "an input folder was modified";
}

INSTANTIATE_TEST_SUITE_P(Cli, OtherBadInput, ::testing::ValuesIn(other_bad_cases()),
                         [](const auto& info) { return info.param.label; });

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ExitsTwoWithOneLineNamingTheFlagAndWritesNothing) {
  const BadCase& c = GetParam();
  Scratch s;
  // An existing, writable output folder: if anything were written, it
  // would be found here.
  const fs::path out = s.dir() / "out";
  fs::create_directories(out);
  auto args = c.args;
  args.push_back("--out");
  args.push_back(out.string());
  const Outcome o = run_cli(args, s.dir());
  EXPECT_EQ(o.code, 2) << "stderr: " << o.err;
  ASSERT_FALSE(o.err.empty());
  EXPECT_EQ(o.err.back(), '\n');
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << "not one line: " << o.err;
  EXPECT_NE(o.err.find(c.names), std::string::npos) << "message does not name '" << c.names << "': " << o.err;
  EXPECT_TRUE(leftovers(out).empty()) << leftovers(out).front();
}

INSTANTIATE_TEST_SUITE_P(Cli, BadInput, ::testing::ValuesIn(bad_cases()),
                         [](const auto& info) { return info.param.label; });

TEST(Cli, UnwritableOutUnderProc) {
  Scratch s;
  auto args = kGood;
  args.insert(args.end(), {"--out", "/proc/cstab_x"});
  const Outcome o = run_cli(args, s.dir());
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_NE(o.err.find("--out"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists("/proc/cstab_x"));
}

TEST(Cli, UnwritableOutUnderARegularFile) {
  Scratch s;
  const fs::path file = s.dir() / "plain";
  std::ofstream(file) << "x\n";
  for (const fs::path& out : {file / "sub", file}) {
    SCOPED_TRACE(out.string());
    auto args = kGood;
    args.insert(args.end(), {"--out", out.string()});
    const Outcome o = run_cli(args, s.dir());
    EXPECT_EQ(o.code, 2) << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    EXPECT_NE(o.err.find("--out"), std::string::npos) << o.err;
    EXPECT_EQ(slurp(file), "x\n");
    EXPECT_TRUE(leftovers(s.dir()).empty()) << leftovers(s.dir()).front();
  }
}

// An existing folder that cannot take files, with --no-series: the folder
// must be found unwritable before the run (exit 2), not after it.
TEST(Cli, UnwritableOutWithoutSeries) {
  Scratch s;
  auto args = kGood;
  args.insert(args.end(), {"--no-series", "--out", "/proc"});
  const Outcome o = run_cli(args, s.dir());
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_NE(o.err.find("--out"), std::string::npos) << o.err;
}

TEST(Cli, NoArgumentsPrintsUsageAndExitsTwo) {
  Scratch s;
  const Outcome o = run_cli({}, s.dir());
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("usage"), std::string::npos);
  const Outcome u = run_cli({"frobnicate"}, s.dir());
  EXPECT_EQ(u.code, 2);
  EXPECT_NE(u.err.find("frobnicate"), std::string::npos);
}

// ---------------------------------------------------------------------------
// A good run

const std::vector<std::string> kSeriesPrefix = {
    "t",     "x",        "xdot",  "z",                "zdot",             "theta",
    "thetadot", "phi",   "phidot", "alpha",           "residual_contact", "residual_rolling",
    "residual_tangency", "energy_drift"};

const std::vector<std::string> kSummaryColumns = {
    "problem", "formulation", "method", "params", "integrator", "step", "rtol", "atol", "status", "reason",
    "fail_time", "t_end", "t_reached", "steps", "rejected_steps", "rhs_evals", "wall_seconds",
    "observe_seconds", "max_residual", "final_residual", "max_energy_drift", "final_energy_drift", "energy_law",
    "max_condition", "ref_time", "ref_error", "ref_scd", "max_residual_contact", "max_residual_rolling",
    "max_residual_tangency", "final_residual_contact", "final_residual_rolling", "final_residual_tangency"};

TEST(Cli, GoodRunWritesDocumentedFiles) {
  Scratch s;
  const fs::path out = s.dir() / "nested" / "run";  // created by cstab
  auto args = with(kGood, "--t-end", "0.5");
  args.insert(args.end(), {"--times", "0.1234,0.25", "--times", "0.3337", "--out", out.string()});
  const Outcome o = run_cli(args, s.dir());
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_TRUE(o.err.empty()) << o.err;
  ASSERT_TRUE(fs::exists(out / "summary.csv"));
  ASSERT_TRUE(fs::exists(out / "series.csv"));
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();

  // summary.csv: one header, one row, every documented column.
  const Csv sum = read_csv(out / "summary.csv");
  ASSERT_EQ(sum.rows.size(), 1u);
  for (const auto& c : kSummaryColumns) EXPECT_GE(sum.col(c), 0) << "summary lacks " << c;
  auto get = [&](const std::string& c) { return sum.col(c) >= 0 ? sum.rows[0][size_t(sum.col(c))] : ""; };
  // params contains ';' but no comma: a plain split is fine.
  ASSERT_EQ(sum.rows[0].size(), sum.header.size());
  EXPECT_EQ(get("problem"), "wheel");
  EXPECT_EQ(get("formulation"), "state-space");
  EXPECT_EQ(get("method"), "pesterev");
  EXPECT_EQ(get("integrator"), "rk4");
  EXPECT_EQ(get("status"), "ok");
  EXPECT_EQ(get("energy_law"), "yes");
  EXPECT_EQ(num(get("step")), 1e-3);
  EXPECT_EQ(get("rtol"), "");
  EXPECT_EQ(num(get("t_reached")), 0.5);
  EXPECT_EQ(num(get("steps")), 500);
  EXPECT_NE(get("params").find("lambda=6"), std::string::npos) << get("params");

  // series.csv: the documented columns, in order.
  const Csv ser = read_csv(out / "series.csv");
  ASSERT_GE(ser.header.size(), kSeriesPrefix.size());
  for (size_t i = 0; i < kSeriesPrefix.size(); ++i) EXPECT_EQ(ser.header[i], kSeriesPrefix[i]) << "column " << i;
  ASSERT_GT(ser.rows.size(), 10u);
  for (const auto& r : ser.rows) ASSERT_EQ(r.size(), ser.header.size());

  // First row: t = 0, on the manifold, no energy drift.
  EXPECT_EQ(num(ser.rows.front()[0]), 0.0);
  EXPECT_EQ(num(ser.rows.front()[size_t(ser.col("energy_drift"))]), 0.0);
  for (const char* c : {"residual_contact", "residual_rolling", "residual_tangency"})
    EXPECT_LT(std::abs(num(ser.rows.front()[size_t(ser.col(c))])), 1e-15) << c;

  // Rows at exactly the requested times and at t_end.
  for (const char* t : {"0.1234", "0.25", "0.3337", "0.5"}) {
    const double want = std::strtod(t, nullptr);
    int hits = 0;
    for (const auto& r : ser.rows) hits += num(r[0]) == want;
    EXPECT_GE(hits, 1) << "no row at t = " << t;
  }

  // The summary agrees with the series: series residuals never exceed the
  // recorded maxima, and the last row carries the final residuals.
  for (const char* c : {"contact", "rolling", "tangency"}) {
    const double mx = num(get(std::string("max_residual_") + c));
    const double fin = num(get(std::string("final_residual_") + c));
    const size_t col = size_t(ser.col(std::string("residual_") + c));
    for (const auto& r : ser.rows) EXPECT_LE(std::abs(num(r[col])), mx) << c << " at t=" << r[0];
    EXPECT_EQ(std::abs(num(ser.rows.back()[col])), fin) << c;
  }
  EXPECT_EQ(num(ser.rows.back()[0]), 0.5);
  const double max_drift = num(get("max_energy_drift"));
  for (const auto& r : ser.rows) EXPECT_LE(std::abs(num(r[size_t(ser.col("energy_drift"))])), max_drift);
}

// Output times between grid points are reached by a side step that does
// not disturb the trajectory: the t_end row is identical with and without
// --times, and an output time equals the final state of a run ending there.
TEST(Cli, TimesDoNotDisturbTheTrajectory) {
  Scratch s;
  auto a = with(kGood, "--t-end", "0.4");
  a.insert(a.end(), {"--times", "0.1234,0.2718", "--out", (s.dir() / "a").string()});
  auto b = with(kGood, "--t-end", "0.4");
  b.insert(b.end(), {"--out", (s.dir() / "b").string()});
  auto c = with(kGood, "--t-end", "0.2718");
  c.insert(c.end(), {"--out", (s.dir() / "c").string()});
  ASSERT_EQ(run_cli(a, s.dir()).code, 0);
  ASSERT_EQ(run_cli(b, s.dir()).code, 0);
  ASSERT_EQ(run_cli(c, s.dir()).code, 0);
  const Csv sa = read_csv(s.dir() / "a" / "series.csv");
  const Csv sb = read_csv(s.dir() / "b" / "series.csv");
  const Csv sc = read_csv(s.dir() / "c" / "series.csv");
  ASSERT_FALSE(sa.rows.empty());
  ASSERT_FALSE(sb.rows.empty());
  ASSERT_FALSE(sc.rows.empty());
  // Coordinates and residuals (not cond, which is a derived diagnostic).
  for (size_t i = 0; i < kSeriesPrefix.size(); ++i) EXPECT_EQ(sa.rows.back()[i], sb.rows.back()[i]) << sa.header[i];
  const std::vector<std::string>* at = nullptr;
  for (const auto& r : sa.rows)
    if (num(r[0]) == 0.2718) at = &r;
  ASSERT_NE(at, nullptr);
  for (size_t i = 0; i < kSeriesPrefix.size(); ++i) EXPECT_EQ((*at)[i], sc.rows.back()[i]) << sa.header[i];
}

// ---------------------------------------------------------------------------
// --help, generated from the declarations that parse the options

// What each command must offer (README, docs/cli.md, the scripts use them).
const std::map<std::string, std::set<std::string>> kCommandOptions = {
    {"list", {}},
    {"run",
     {"--problem", "--problem-param", "--method", "--formulation", "--param", "--integrator", "--step", "--rtol",
      "--atol", "--t-end",
      "--times", "--sample-every", "--ref-time", "--blowup", "--observe-every", "--perturb", "--recovery-threshold",
      "--drift-fit-from", "--max-steps", "--no-series", "--out"}},
    {"stability",
     {"--problem", "--problem-param", "--method", "--formulation", "--param", "--integrator", "--gain-param",
      "--steps", "--gains",
      "--t-end", "--perturb", "--blowup", "--bisect", "--max-steps", "--no-plot", "--out"}},
    {"tune",
     {"--problem", "--problem-param", "--method", "--formulation", "--param", "--integrator", "--t-end", "--target",
      "--measure", "--steps", "--tols", "--gains", "--repeats", "--cost", "--perturb", "--blowup", "--prune-ratio",
      "--max-runs", "--max-steps", "--no-plot", "--out"}},
    {"score",
     {"--problem", "--problem-param", "--formulation", "--label", "--ref-time", "--wall-seconds", "--sample-every",
      "--blowup", "--recovery-threshold", "--drift-fit-from", "--no-series", "--out"}},
    {"matrix",
     {"--out", "--jobs", "--shard", "--filter", "--force", "--no-report", "--svg", "--keep-series", "--list",
      "--print-default"}},
    {"merge", {"--jobs", "--no-report", "--svg"}},
    {"report", {"--jobs", "--no-plots", "--svg"}},
    {"gate",
     {"--thresholds", "--csv", "--update", "--init", "--add-missing", "--strict", "--factor", "--time-factor",
      "--recovery-factor"}},
};

// One option line of a --help: "  --step H      fixed step, for euler, rk4".
struct HelpOption {
  std::string name;
  bool takes_value = false;  // a metavar follows the name
  std::string description;
};

bool all_caps(const std::string& word) {
  return std::none_of(word.begin(), word.end(), [](char c) { return std::islower(static_cast<unsigned char>(c)); });
}

std::vector<HelpOption> help_options(const std::string& help) {
  std::vector<HelpOption> found;
  std::istringstream lines(help);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("  -", 0) != 0) continue;
    std::istringstream words(line);
    std::string names, word;
    words >> names;  // "-h,--help" or "--step"
    HelpOption o;
    o.name = names.substr(names.find(",--") == std::string::npos ? 0 : names.find(",--") + 1);
    bool first = true;
    while (words >> word) {
      if (first && all_caps(word) && word != "REQUIRED") o.takes_value = true;
      else if (!(o.description.empty() && word == "REQUIRED"))
        o.description += (o.description.empty() ? "" : " ") + word;
      first = false;
    }
    found.push_back(o);
  }
  return found;
}

TEST(CliHelp, EveryCommandListsExactlyItsOptionsWithADescriptionEach) {
  Scratch s;
  for (const auto& [command, expected] : kCommandOptions) {
    SCOPED_TRACE(command);
    const Outcome o = run_cli({command, "--help"}, s.dir());
    EXPECT_EQ(o.code, 0) << o.err;
    EXPECT_TRUE(o.err.empty()) << o.err;
    EXPECT_NE(o.out.find("usage: cstab " + command), std::string::npos) << o.out;
    EXPECT_EQ(o.out.find("`cstab COMMAND --help`"), std::string::npos) << "the top-level footer:\n" << o.out;
    std::set<std::string> listed;
    for (const auto& opt : help_options(o.out)) {
      EXPECT_FALSE(opt.description.empty()) << opt.name << " has no description";
      EXPECT_EQ(opt.description.find('\n'), std::string::npos);
      if (opt.name != "--help") listed.insert(opt.name);
    }
    EXPECT_EQ(listed, expected);
    EXPECT_EQ(run_cli({"help", command}, s.dir()).out, o.out) << "`cstab help " << command << "` differs";
    EXPECT_EQ(run_cli({command, "-h"}, s.dir()).out, o.out);
  }
}

// Every option the help lists is one the parser takes, as listed: with a
// value (`--x=` is then "missing value") or without (`--x=v`: "takes no
// value"); both fail while parsing, before the command runs.
TEST(CliHelp, ListedOptionsParseAsListed) {
  Scratch s;
  for (const auto& [command, expected] : kCommandOptions) {
    for (const auto& opt : help_options(run_cli({command, "--help"}, s.dir()).out)) {
      if (opt.name == "--help") continue;
      SCOPED_TRACE(command + " " + opt.name);
      const Outcome o = run_cli({command, opt.name + (opt.takes_value ? "=" : "=v")}, s.dir());
      EXPECT_EQ(o.code, 2) << o.out << o.err;
      EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
      EXPECT_NE(o.err.find("cstab " + command + ": error: " + opt.name +
                           (opt.takes_value ? ": missing value" : ": takes no value")),
                std::string::npos)
          << o.err;
    }
    const Outcome unknown = run_cli({command, "--not-an-option"}, s.dir());
    EXPECT_EQ(unknown.code, 2);
    EXPECT_NE(unknown.err.find("--not-an-option: unknown option"), std::string::npos) << unknown.err;
  }
}

TEST(CliHelp, TopLevelHelpListsEveryCommand) {
  Scratch s;
  const Outcome help = run_cli({"--help"}, s.dir());
  EXPECT_EQ(help.code, 0) << help.err;
  EXPECT_NE(help.out.find("usage: cstab"), std::string::npos) << help.out;
  for (const auto& [command, options] : kCommandOptions) {
    // "  run    Run one case; ..." in the Commands section.
    const size_t at = help.out.find("\n  " + command + " ");
    ASSERT_NE(at, std::string::npos) << command << " missing from\n" << help.out;
    const std::string line = help.out.substr(at + 1, help.out.find('\n', at + 1) - at - 1);
    EXPECT_NE(line.find_first_not_of(' ', 2 + command.size()), std::string::npos) << "no description: " << line;
  }
  EXPECT_EQ(run_cli({"help"}, s.dir()).out, help.out);
  EXPECT_EQ(run_cli({"help"}, s.dir()).code, 0);
  const Outcome help_help = run_cli({"help", "help"}, s.dir());
  EXPECT_EQ(help_help.code, 0) << help_help.err;
  EXPECT_NE(help_help.out.find("usage: cstab help [OPTIONS] [COMMAND]"), std::string::npos) << help_help.out;
  EXPECT_EQ(run_cli({"-h"}, s.dir()).out, help.out);
  const Outcome bare = run_cli({}, s.dir());  // no command: the same text, but exit 2
  EXPECT_EQ(bare.code, 2);
  EXPECT_EQ(bare.out, help.out);
}

// docs/cli.md documents every option of every command.
TEST(CliHelp, DocsNameEveryOption) {
  const std::string doc = slurp(fs::path(CSTAB_SOURCE_DIR) / "docs" / "cli.md");
  ASSERT_FALSE(doc.empty());
  for (const auto& [command, options] : kCommandOptions) {
    const size_t section = doc.find("## cstab " + command);
    ASSERT_NE(section, std::string::npos) << command;
    const std::string text = doc.substr(section, doc.find("\n## ", section + 1) - section);
    for (const auto& opt : options) EXPECT_NE(text.find(opt + " "), std::string::npos) << command << " " << opt;
  }
}

// ---------------------------------------------------------------------------
// --t-end ref / default, as matrix files read t_end = "ref" / "default"

// "reference: ... (default at t = 5)" in `cstab list`, for `problem`.
double listed_reference_time(const std::string& list, const std::string& problem) {
  const size_t at = list.find("\n  " + problem + ": ");
  if (at == std::string::npos) return std::nan("");
  const size_t ref = list.find("    reference: ", at);
  const size_t t = list.find("(default at t = ", ref);
  if (ref == std::string::npos || t == std::string::npos || t > list.find('\n', ref)) return std::nan("");
  return std::strtod(list.c_str() + t + std::string("(default at t = ").size(), nullptr);
}

Csv summary_of(const std::vector<std::string>& args, const fs::path& scratch, const fs::path& out) {
  auto a = args;
  a.insert(a.end(), {"--no-series", "--out", out.string()});
  const Outcome o = run_cli(a, scratch);
  EXPECT_EQ(o.code, 0) << o.err;
  return read_csv(out / "summary.csv");
}

// The same words as matrix files: "ref" falls back to the default horizon
// for a problem without a reference (none of the registered ones today).
TEST(Args, EndTimeWordsAndNumbers) {
  cstab::ProblemInfo with_ref, without_ref;
  with_ref.reference_time = 3;
  with_ref.default_t_end = 20;
  without_ref.default_t_end = 7;
  using cstab::cli::resolve_end_time;
  EXPECT_EQ(resolve_end_time("ref", with_ref, "--t-end"), 3);
  EXPECT_EQ(resolve_end_time("default", with_ref, "--t-end"), 20);
  EXPECT_EQ(resolve_end_time("ref", without_ref, "--t-end"), 7);
  EXPECT_EQ(resolve_end_time("default", without_ref, "--t-end"), 7);
  EXPECT_EQ(resolve_end_time("0.25", with_ref, "--t-end"), 0.25);
  for (const char* bad : {"REF", "reference", "ref ", "", "nan", "inf", "2s"}) {
    try {
      resolve_end_time(bad, with_ref, "--t-end");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const cstab::UsageError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--t-end: ", 0), 0u) << e.what();
    }
  }
}

TEST(Cli, TEndRefIsTheProblemsReferenceTime) {
  Scratch s;
  const Problem& wheel = find_problem("wheel");
  const double ref = listed_reference_time(run_cli({"list"}, s.dir()).out, "wheel");
  ASSERT_GT(ref, 0) << "cstab list shows no reference time for wheel";
  EXPECT_EQ(ref, wheel.info().reference_time);
  const auto base = with(kGood, "--t-end", "ref");
  const Csv sum = summary_of(base, s.dir(), s.dir() / "ref");
  ASSERT_EQ(sum.rows.size(), 1u);
  EXPECT_EQ(num(sum.rows[0][size_t(sum.col("t_end"))]), ref);
  EXPECT_EQ(num(sum.rows[0][size_t(sum.col("t_reached"))]), ref);
  EXPECT_EQ(num(sum.rows[0][size_t(sum.col("ref_time"))]), ref);
  EXPECT_FALSE(std::isnan(num(sum.rows[0][size_t(sum.col("ref_error"))])));

  const Csv def = summary_of(with(base, "--t-end", "default"), s.dir(), s.dir() / "default");
  ASSERT_EQ(def.rows.size(), 1u);
  EXPECT_EQ(num(def.rows[0][size_t(def.col("t_end"))]), wheel.info().default_t_end);
}

// The series is a time series: strictly increasing t, one row per time.
// DISABLED: fails today -- an output time that is a grid point gets two rows
// (the step's sample row and the output row), and a grid point that lands
// 1 ulp past an output time (0.7000000000000001 for 700 * 1e-3) precedes the
// output row at 0.7. See the fix proposed for harness/run.cpp and
// harness/integrator.cpp.
TEST(Cli, SeriesTimesStrictlyIncrease) {
  Scratch s;
  auto a = with(kGood, "--t-end", "1");
  a.insert(a.end(), {"--times", "0.1,0.3,0.35,0.7", "--out", s.dir().string()});
  ASSERT_EQ(run_cli(a, s.dir()).code, 0);
  const Csv ser = read_csv(s.dir() / "series.csv");
  for (size_t i = 1; i < ser.rows.size(); ++i)
    EXPECT_LT(num(ser.rows[i - 1][0]), num(ser.rows[i][0])) << "rows " << i - 1 << " and " << i;
}

}  // namespace

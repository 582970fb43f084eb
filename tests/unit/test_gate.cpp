// The regression gate: thresholds files are validated with file:line:column
// errors; `cstab gate` passes exactly when every bound holds, with values
// and ratios computed from the results folder; --update / --init re-baseline;
// the committed thresholds pass on the gate matrix, and degraded
// configurations (stabilization off, a gain of 0, a 10x step) fail them for
// the right reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "gate/gate.hpp"
#include "matrix/matrix.hpp"
#include "matrix/results.hpp"
#include "tests/support/test_util.hpp"

namespace fs = std::filesystem;
using cstab::ThresholdsFile;
using cstab::UsageError;
using cstab::testing::cstab_cmd;
using cstab::testing::exit_code;
using cstab::testing::Outcome;
using cstab::testing::quote;
using cstab::testing::Scratch;
using cstab::testing::slurp;

namespace {

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

const std::string kCommitted = std::string(CSTAB_SOURCE_DIR) + "/matrices/gate-thresholds.csv";
const std::string kHeader =
    "problem,method,integrator,setting,params,status,max_residual,max_energy_drift,max_ref_error,min_ref_scd\n";

// The message of the UsageError parse_thresholds throws for `text`.
std::string parse_error(const std::string& text) {
  try {
    cstab::parse_thresholds(text, "t.csv");
  } catch (const UsageError& e) {
    return e.what();
  }
  return "(no error)";
}

// ---------------------------------------------------------------- parsing

TEST(GateThresholds, CommittedFileParsesAndRoundTripsVerbatim) {
  const std::string text = slurp(kCommitted);
  const ThresholdsFile f = cstab::parse_thresholds(text, kCommitted);
  EXPECT_GE(f.rows.size(), 50u);
  std::map<std::string, int> per_problem;
  for (const auto& r : f.rows) ++per_problem[r.problem];
  for (const char* p : {"wheel", "ball", "biped", "slider-crank", "andrews", "car-axis", "pendulum"})
    EXPECT_GE(per_problem[p], 5) << p;
  // Rewriting without changes reproduces the file (comments included).
  EXPECT_EQ(cstab::thresholds_text(f), text);
}

TEST(GateThresholds, ErrorsNameFileLineAndColumn) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"problem,method,integrator,setting,max_residul\n", "t.csv:1:5: unknown column 'max_residul'"},
      {"problem,method,integrator\n", "t.csv:1: missing required column 'setting'"},
      {"problem,method,integrator,setting,problem\n", "t.csv:1:5: column 'problem' appears twice"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,ok,abc,,,\n", "t.csv:2:7: max_residual: 'abc' is not a number"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,ok,1e-8x,,,\n", "t.csv:2:7: max_residual: '1e-8x' is not a number"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,ok,,-1e-6,,\n", "t.csv:2:8: max_energy_drift: -1e-6 is negative"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,ok,,,nan,\n", "t.csv:2:9: max_ref_error: 'nan' is not finite"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,ok,,,,inf\n", "t.csv:2:10: min_ref_scd: 'inf' is not finite"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,fine,,,,\n", "t.csv:2:6: status: 'fine' is not one of"},
      {kHeader + "wheel,baumgarte,rk4,,,ok,,,,\n", "t.csv:2:4: setting: required, empty"},
      {kHeader + "# a comment\nwheel,baumgarte,rk4,step=0.001,,ok,1e-8,,,\n\nwheel,baumgarte,rk4,step=0.001,,ok,1e-7,,,\n",
       "t.csv:5: duplicate case wheel baumgarte rk4 step=0.001 (first at line 3)"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001,,ok,,,,,7\n", "t.csv:2: more cells than the header's 10 columns"},
      {kHeader + "wheel,baumgarte,rk4,step=0.001\n", "t.csv:2: fewer cells than the header's 10 columns"},
      {kHeader + "wheel,baumgarte,rk4,\"step=0.001,,ok,,,,\n", "t.csv:2: unterminated quoted cell"},
      {"problem,method,integrator,setting,name,baseline,max_time_ratio\nwheel,none,rk4,step=0.001,a,b,2\n",
       "t.csv:2:6: baseline 'b' is not the name of any row"},
      {"problem,method,integrator,setting,max_time_ratio\nwheel,none,rk4,step=0.001,2\n",
       "t.csv:2:5: max_time_ratio needs a baseline"},
      {"problem,method,integrator,setting,name\nwheel,none,rk4,step=0.001,a\nwheel,none,rk4,step=0.01,a\n",
       "t.csv:3:5: duplicate name 'a' (first at line 2)"},
      {"# only comments\n\n", "t.csv: no header line"},
  };
  for (const auto& c : cases) {
    const std::string msg = parse_error(c.text);
    EXPECT_NE(msg.find(c.expected), std::string::npos) << "input:\n" << c.text << "message: " << msg;
  }
}

TEST(GateThresholds, QuotedCellsAndCommentsAreAccepted) {
  const ThresholdsFile f = cstab::parse_thresholds(
      "# why these bounds\nproblem , method,integrator,setting,params,note\n"
      "wheel, baumgarte ,rk4,step=0.001,\"alpha=5;beta=5\",\"a note, with a comma\"\n",
      "t.csv");
  ASSERT_EQ(f.rows.size(), 1u);
  EXPECT_EQ(f.rows[0].method, "baumgarte");
  EXPECT_EQ(f.rows[0].params, "alpha=5;beta=5");
  EXPECT_EQ(f.rows[0].line, 3);
  EXPECT_TRUE(std::isnan(f.rows[0].max_residual));
}

TEST(GateThresholds, KeyValuesCompareNumbersAsNumbers) {
  EXPECT_TRUE(cstab::same_key_values("step=1e-3", "step=0.001"));
  EXPECT_TRUE(cstab::same_key_values("step=0.001;perturb=1e-3", "perturb=0.001;step=1E-3"));
  EXPECT_TRUE(cstab::same_key_values("alpha=5;beta=5", "beta=5.0;alpha=5"));
  EXPECT_TRUE(cstab::same_key_values("", ""));
  EXPECT_FALSE(cstab::same_key_values("step=1e-3", "step=1e-4"));
  EXPECT_FALSE(cstab::same_key_values("step=1e-3", "tol=1e-3"));
  EXPECT_FALSE(cstab::same_key_values("step=1e-3", "step=1e-3;perturb=0.001"));
  EXPECT_FALSE(cstab::same_key_values("form=a", "form=b"));
  EXPECT_EQ(cstab::canonical_key_values("step=1e-3;alpha=5.0"), "alpha=5;step=0.001");
}

TEST(GateThresholds, StatusNamesRoundTrip) {
  using cstab::Status;
  for (Status s : {Status::kOk, Status::kDiverged, Status::kFailed, Status::kTimeout, Status::kCrashed,
                   Status::kInvalid, Status::kNotRun}) {
    const auto back = cstab::parse_status(cstab::status_name(s));
    ASSERT_TRUE(back.has_value()) << cstab::status_name(s);
    EXPECT_EQ(*back, s) << cstab::status_name(s);
  }
  EXPECT_STREQ(cstab::status_name(Status::kNotRun), "not run");
  EXPECT_FALSE(cstab::parse_status("fine").has_value());
  EXPECT_FALSE(cstab::parse_status("OK").has_value());
  EXPECT_EQ(cstab::status_from_cell("timeout"), Status::kTimeout);
  EXPECT_EQ(cstab::status_from_cell("not run"), Status::kFailed);  // never written: not a result
  EXPECT_TRUE(cstab::is_gateable(Status::kDiverged));
  EXPECT_FALSE(cstab::is_gateable(Status::kInvalid));
  EXPECT_FALSE(cstab::is_gateable(Status::kTimeout));
}

// The loader the gate and the report share, on a hand-written folder: a
// case whose second repeat diverged is diverged (with that repeat's
// reason), its median is over the ok repeats only; a case without a whole
// case.txt (a folder of an older cstab, a record edited after it was
// written) is not run; "1e-3" in the summary rows reads as 0.001.
TEST(GateThresholds, ResultsModelFoldsRepeats) {
  Scratch s("cstab_model");
  const std::string dir = (s.dir() / "r").string();
  std::vector<cstab::CaseEntry> entries(4);
  for (size_t i = 0; i < entries.size(); ++i) {
    entries[i].index = i;
    entries[i].id = "000000000000000" + std::to_string(i);
    entries[i].problem = "wheel";
    entries[i].method = "baumgarte";
    entries[i].integrator = "rk4";
    entries[i].setting = "step=0.001";
    entries[i].t_end = 1;
    entries[i].repeats = 3;
    entries[i].curve = "baumgarte/rk4";
    fs::create_directories(dir + "/cases/" + entries[i].id);
  }
  cstab::write_manifest(dir + "/cases.csv", entries, entries.size());
  const std::string head = "case_id,repeat,status,reason,step,wall_seconds,max_residual,energy_law,max_energy_drift\n";
  const auto record = [&](const std::string& id, const std::string& rows) {
    write(dir + "/cases/" + id + "/case.txt", cstab::case_record_text("k\n", rows));
  };
  record("0000000000000000",
         head + "0000000000000000,0,ok,,1e-3,0.5,1e-9,yes,1e-6\n0000000000000000,1,ok,,1e-3,0.25,2e-9,yes,1e-6\n"
                "0000000000000000,2,diverged,residual above 1e3,1e-3,0.1,5e3,yes,\n");
  record("0000000000000001",
         "case_id,repeat,status,reason,t_end\n0000000000000001,0,timeout,killed after 1 s (timeout),1\n");
  // As an older cstab wrote it: incomplete.
  write(dir + "/cases/0000000000000002/summary.csv", head + "0000000000000002,0,ok,,1e-3,0.5,1e-9,yes,1e-6\n");
  write(dir + "/cases/0000000000000002/key.txt", "k\n");
  // A number edited after the record was written: incomplete.
  {
    std::string text = cstab::case_record_text("k\n", head + "0000000000000003,0,ok,,1e-3,0.5,1e-9,yes,1e-6\n");
    text.replace(text.find("1e-9"), 4, "1e-8");  // same size: the hash tells
    write(dir + "/cases/0000000000000003/case.txt", text);
  }
  const cstab::ResultsFolder f = cstab::load_results_folder(dir);
  ASSERT_EQ(f.cases.size(), 4u);
  const cstab::CaseResult& a = f.cases[0];
  EXPECT_TRUE(a.complete);
  EXPECT_EQ(a.status, cstab::Status::kDiverged);
  EXPECT_EQ(a.reason, "residual above 1e3");
  EXPECT_EQ(a.repeats.size(), 3u);
  EXPECT_EQ(a.ok_repeats, 2);
  EXPECT_DOUBLE_EQ(a.wall_median, 0.375);
  EXPECT_EQ(a.wall_min, 0.25);
  EXPECT_EQ(a.wall_max, 0.5);
  EXPECT_EQ(a.step, 0.001);
  EXPECT_EQ(a.max_residual, 5e3);  // the largest over the repeats
  EXPECT_EQ(a.drift, 1e-6);
  EXPECT_EQ(a.steps, -1);  // no steps column: not recorded
  const cstab::CaseResult& b = f.cases[1];
  EXPECT_TRUE(b.complete);
  EXPECT_EQ(b.status, cstab::Status::kTimeout);
  EXPECT_TRUE(std::isnan(b.wall_median));
  EXPECT_TRUE(std::isnan(b.max_residual));
  for (size_t i : {2, 3}) {
    const cstab::CaseResult& c = f.cases[i];
    EXPECT_FALSE(c.complete) << i;
    EXPECT_EQ(c.status, cstab::Status::kNotRun) << i;
  }
  // DIR/summary.csv: the complete cases' rows as written, the sweep after "repeat".
  EXPECT_EQ(cstab::write_matrix_summary(dir, f.entries), 2u);
  const cstab::CsvTable t = cstab::read_csv(dir + "/summary.csv");
  ASSERT_EQ(t.rows.size(), 4u);
  EXPECT_EQ(t.header[2], "sweep");
  EXPECT_EQ(t.get(0, "step"), "1e-3");
  EXPECT_EQ(t.get(3, "status"), "timeout");
}

// A manifest with a cell that is not a number is not a results folder (a
// UsageError naming the file, row and column), for the gate and the report alike.
TEST(GateThresholds, ManifestNumbersAreChecked) {
  Scratch s("cstab_manifest");
  const std::string dir = s.dir().string();
  const std::string head = "index,case_id,sweep,problem,method,formulation,integrator,params,setting,t_end,repeats,"
                           "work_precision,overlay,curve,selected_cases\n";
  write(dir + "/cases.csv", head + "0,0000000000000000,a,wheel,baumgarte,,rk4,,step=0.001,1e-1,3,1,0,c,1\n");
  const auto entries = cstab::read_results_manifest(dir);
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0].t_end, 0.1);
  EXPECT_EQ(entries[0].repeats, 3);
  // Errors name file:line:column of the bad cell (issue 16).
  for (const auto& [row, what] : std::vector<std::pair<std::string, std::string>>{
           {"0,0000000000000000,a,wheel,baumgarte,,rk4,,step=0.001,soon,3,1,0,c,1", ":2:%d: t_end: 'soon' is not a number"},
           {"0,0000000000000000,a,wheel,baumgarte,,rk4,,step=0.001,1,2.5,1,0,c,1", ":2:%d: repeats: '2.5' is not a count"},
           {"x,0000000000000000,a,wheel,baumgarte,,rk4,,step=0.001,1,3,1,0,c,1", ":2:1: index: 'x' is not a count"},
           {"0,00000000000000zz,a,wheel,baumgarte,,rk4,,step=0.001,1,3,1,0,c,1",
            ":2:3: case_id: '00000000000000zz' is not a case id (16 hex digits)"}}) {
    std::string expected = what;
    const size_t pct = expected.find("%d");
    if (pct != std::string::npos)
      expected.replace(pct, 2, std::to_string(expected.find("t_end") != std::string::npos ? 55 : 57));
    write(dir + "/cases.csv", head + row + "\n");
    try {
      cstab::read_results_manifest(dir);
      ADD_FAILURE() << row;
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("cases.csv" + expected), std::string::npos) << e.what();
    }
  }
}

// ------------------------------------------------- gate on a small matrix

// Two wheel cases, run once per test suite.
class GateEvaluate : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new Scratch("cstab_gate");
    dir_ = (scratch_->dir() / "results").string();
    write(scratch_->dir() / "m.toml",
          "[defaults]\nproblems = [\"wheel\"]\nt_end = \"ref\"\nseries = false\n"
          "[[sweep]]\nmethods = [\"baumgarte\", \"none\"]\nintegrators = \"rk4\"\nstep = 1e-3\nrepeats = 3\n"
          "[[sweep]]\nmethods = [\"minimal\"]\nintegrators = \"rk8pd\"\ntol = 1e-10\nrepeats = 3\n");
    const Outcome o = cstab_cmd("matrix " + quote((scratch_->dir() / "m.toml").string()) + " --out " + quote(dir_) +
                                " --jobs 2 --no-report");
    ASSERT_EQ(o.code, 0) << o.out;
  }
  static void TearDownTestSuite() { delete scratch_; }

  // The summary rows of one case (method, integrator) of the results folder.
  static std::vector<std::map<std::string, std::string>> rows_of(const std::string& method) {
    const cstab::CsvTable t = cstab::read_csv(dir_ + "/summary.csv");
    std::vector<std::map<std::string, std::string>> out;
    for (size_t i = 0; i < t.rows.size(); ++i) {
      if (t.get(i, "method") != method) continue;
      std::map<std::string, std::string> row;
      for (const auto& h : t.header) row[h] = t.get(i, h);
      out.push_back(row);
    }
    return out;
  }
  static double median_wall(const std::string& method) {
    std::vector<double> w;
    for (const auto& r : rows_of(method)) w.push_back(std::stod(r.at("wall_seconds")));
    std::sort(w.begin(), w.end());
    return w.size() % 2 ? w[w.size() / 2] : 0.5 * (w[w.size() / 2 - 1] + w[w.size() / 2]);
  }
  static Outcome gate(const std::string& thresholds_text, const std::string& extra = "") {
    const fs::path p = scratch_->dir() / "th.csv";
    write(p, thresholds_text);
    return cstab_cmd("gate --thresholds " + quote(p.string()) + " " + extra + " " + quote(dir_));
  }

  static Scratch* scratch_;
  static std::string dir_;
};
Scratch* GateEvaluate::scratch_ = nullptr;
std::string GateEvaluate::dir_;

TEST_F(GateEvaluate, PassesWhenEveryBoundHoldsAndFailsOnOneThatDoesNot) {
  const double residual = std::stod(rows_of("baumgarte").at(0).at("max_residual"));
  ASSERT_GT(residual, 0);
  char loose[64], tight[64];
  std::snprintf(loose, sizeof loose, "%.6g", residual * 2);
  std::snprintf(tight, sizeof tight, "%.6g", residual / 2);
  const std::string head = "problem,method,integrator,setting,max_residual\n";
  const Outcome pass = gate(head + "wheel,baumgarte,rk4,step=0.001," + loose + "\n");
  EXPECT_EQ(pass.code, 0) << pass.out;
  EXPECT_NE(pass.out.find("max_residual"), std::string::npos);
  EXPECT_NE(pass.out.find("x2"), std::string::npos) << pass.out;  // margin = threshold / value
  EXPECT_NE(pass.out.find("2 checks, 0 failed"), std::string::npos) << pass.out;

  const Outcome fail = gate(head + "wheel,baumgarte,rk4,step=0.001," + tight + "\n");
  EXPECT_EQ(fail.code, 1) << fail.out;
  EXPECT_NE(fail.out.find("FAIL"), std::string::npos);
  EXPECT_NE(fail.out.find("x0.5"), std::string::npos) << fail.out;
  EXPECT_NE(fail.out.find("2 checks, 1 failed"), std::string::npos) << fail.out;
}

TEST_F(GateEvaluate, MissingCaseFailsAndIsNamed) {
  const Outcome o = gate("problem,method,integrator,setting,max_residual\n"
                         "wheel,baumgarte,rk4,step=1e-2,1\n"  // the folder has step=0.001 only
                         "ball,baumgarte,rk4,step=0.001,1\n");
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("wheel baumgarte rk4 step=1e-2"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("no such case in the results folder; it has wheel baumgarte rk4 at step=0.001"),
            std::string::npos)
      << o.out;
  EXPECT_NE(o.out.find("ball baumgarte rk4 step=0.001"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("2 checks, 2 failed"), std::string::npos) << o.out;
}

// The results model reads the folder back: statuses, repeats, the median
// of the ok repeats' wall times, numbers as written.
TEST_F(GateEvaluate, ResultsFolderLoadsEveryCase) {
  const cstab::ResultsFolder f = cstab::load_results_folder(dir_);
  ASSERT_EQ(f.cases.size(), 3u);
  ASSERT_EQ(f.entries.size(), 3u);
  bool saw_baumgarte = false, saw_none = false, saw_minimal = false;
  for (size_t i = 0; i < f.cases.size(); ++i) {
    const cstab::CaseResult& c = f.cases[i];
    EXPECT_EQ(c.entry, &f.entries[i]);
    ASSERT_TRUE(c.complete) << c.entry->label();
    if (c.entry->method == "baumgarte") {
      saw_baumgarte = true;
      EXPECT_EQ(c.status, cstab::Status::kOk);
      EXPECT_EQ(c.repeats.size(), 3u);
      EXPECT_EQ(c.ok_repeats, 3);
      EXPECT_EQ(c.wall_median, median_wall("baumgarte"));
      EXPECT_LE(c.wall_min, c.wall_median);
      EXPECT_GE(c.wall_max, c.wall_median);
      EXPECT_EQ(c.step, 0.001);
      EXPECT_TRUE(std::isnan(c.rtol));
      EXPECT_EQ(c.max_residual, std::stod(rows_of("baumgarte").at(0).at("max_residual")));
      EXPECT_EQ(c.steps, std::stol(rows_of("baumgarte").at(0).at("steps")));
      EXPECT_TRUE(c.energy_law);
      EXPECT_EQ(c.drift_name, "energy");
      EXPECT_EQ(c.drift, c.max_energy_drift);
    }
    if (c.entry->method == "none") {  // unstabilized, but finishes (the status test expects ok)
      saw_none = true;
      EXPECT_EQ(c.status, cstab::Status::kOk);
      EXPECT_EQ(c.ok_repeats, 3);
      EXPECT_EQ(c.wall_median, median_wall("none"));
      EXPECT_TRUE(c.reason.empty());
    }
    if (c.entry->method == "minimal") {
      saw_minimal = true;
      EXPECT_EQ(c.rtol, 1e-10);
      EXPECT_TRUE(std::isnan(c.step));
      EXPECT_GT(c.rhs_evals, 0);
    }
  }
  EXPECT_TRUE(saw_baumgarte && saw_none && saw_minimal);
}

// Keys are matched by meaning: step "1e-3" names the folder's step=0.001
// case, and the two spellings in one file are the same case.
TEST_F(GateEvaluate, SettingNumbersMatchAsNumbers) {
  const std::string head = "problem,method,integrator,setting,max_residual\n";
  for (const char* setting : {"step=1e-3", "step=0.0010", "step=1.0e-03"}) {
    const Outcome o = gate(head + "wheel,baumgarte,rk4," + setting + ",1\n");
    EXPECT_EQ(o.code, 0) << setting << "\n" << o.out;
    EXPECT_NE(o.out.find("2 checks, 0 failed"), std::string::npos) << setting << "\n" << o.out;
    EXPECT_EQ(o.out.find("no such case"), std::string::npos) << setting << "\n" << o.out;
  }
  const Outcome near = gate(head + "wheel,baumgarte,rk4,step=0.0011,1\n");  // a different number
  EXPECT_EQ(near.code, 1) << near.out;
  EXPECT_NE(near.out.find("no such case in the results folder"), std::string::npos) << near.out;
  const Outcome dup = gate(head + "wheel,baumgarte,rk4,step=1e-3,1\nwheel,baumgarte,rk4,step=0.001,1\n");
  EXPECT_EQ(dup.code, 2) << dup.out;
  EXPECT_NE(dup.out.find("duplicate case"), std::string::npos) << dup.out;
}

TEST_F(GateEvaluate, ExpectedStatusAndMissingValuesAreChecked) {
  // The wheel has no first integral besides energy: a bound on one cannot pass.
  const Outcome o = gate("problem,method,integrator,setting,status,max_integral_drift\n"
                         "wheel,none,rk4,step=0.001,diverged,\n"
                         "wheel,baumgarte,rk4,step=0.001,ok,1\n");
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.out.find("status              ok     diverged"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("the case has no value for it"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("3 checks, 2 failed"), std::string::npos) << o.out;
}

TEST_F(GateEvaluate, TimeRatioIsTheRatioOfMedianWallTimes) {
  const double ratio = median_wall("baumgarte") / median_wall("minimal");
  ASSERT_GT(ratio, 0);
  const fs::path csv = scratch_->dir() / "gate.csv";
  const Outcome o = gate("name,problem,method,integrator,setting,baseline,max_time_ratio\n"
                         "base,wheel,minimal,rk8pd,tol=1e-10,,\n"
                         "fast,wheel,baumgarte,rk4,step=0.001,base,1e9\n"
                         "slow,wheel,baumgarte,rk4,step=0.001,base,1e-9\n",
                         "--csv " + quote(csv.string()));
  // Rows 2 and 3 name the same case: a duplicate, refused before any check.
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("duplicate case"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(csv));

  const Outcome ok = gate("name,problem,method,integrator,setting,baseline,max_time_ratio\n"
                          "base,wheel,minimal,rk8pd,tol=1e-10,,\n"
                          "fast,wheel,baumgarte,rk4,step=0.001,base,1e9\n",
                          "--csv " + quote(csv.string()));
  EXPECT_EQ(ok.code, 0) << ok.out;
  const cstab::CsvTable t = cstab::read_csv(csv.string());
  bool found = false;
  for (size_t i = 0; i < t.rows.size(); ++i)
    if (t.get(i, "check") == "max_time_ratio") {
      found = true;
      EXPECT_NEAR(std::stod(t.get(i, "value")), ratio, 2e-3 * ratio);
      EXPECT_EQ(t.get(i, "result"), "pass");
    }
  EXPECT_TRUE(found);
}

TEST_F(GateEvaluate, UpdateRebaselinesWithTheFactorAndInitWritesAPassingFile) {
  const double residual = std::stod(rows_of("baumgarte").at(0).at("max_residual"));
  const double scd = std::stod(rows_of("baumgarte").at(0).at("ref_scd"));
  const fs::path p = scratch_->dir() / "th.csv";
  write(p, "# kept\nproblem,method,integrator,setting,max_residual,min_ref_scd,note\n"
           "wheel,baumgarte,rk4,step=0.001,1e-30,17,keep this note\n");
  EXPECT_EQ(cstab_cmd("gate --thresholds " + quote(p.string()) + " " + quote(dir_)).code, 1);
  const Outcome up = cstab_cmd("gate --update --factor 10 --thresholds " + quote(p.string()) + " " + quote(dir_));
  ASSERT_EQ(up.code, 0) << up.out;
  EXPECT_NE(up.out.find("max_residual: 1e-30 -> "), std::string::npos) << up.out;
  EXPECT_NE(up.out.find("2 thresholds changed"), std::string::npos) << up.out;
  const ThresholdsFile f = cstab::read_thresholds_file(p.string());
  ASSERT_EQ(f.rows.size(), 1u);
  EXPECT_GE(f.rows[0].max_residual, 10 * residual);
  EXPECT_LE(f.rows[0].max_residual, 10.1 * residual);
  EXPECT_LE(f.rows[0].min_ref_scd, scd - 1);
  EXPECT_GE(f.rows[0].min_ref_scd, scd - 1.01);
  const std::string text = slurp(p);
  EXPECT_EQ(text.rfind("# kept\n", 0), 0u) << text;
  EXPECT_NE(text.find("keep this note"), std::string::npos);
  EXPECT_EQ(cstab_cmd("gate --thresholds " + quote(p.string()) + " " + quote(dir_)).code, 0);

  const fs::path init = scratch_->dir() / "init.csv";
  const Outcome in = cstab_cmd("gate --init " + quote(init.string()) + " " + quote(dir_));
  ASSERT_EQ(in.code, 0) << in.out;
  EXPECT_NE(in.out.find("3 cases"), std::string::npos) << in.out;
  const Outcome again = cstab_cmd("gate --thresholds " + quote(init.string()) + " " + quote(dir_));
  EXPECT_EQ(again.code, 0) << again.out;
  // --init never overwrites.
  EXPECT_EQ(cstab_cmd("gate --init " + quote(init.string()) + " " + quote(dir_)).code, 2);
}

TEST_F(GateEvaluate, BadInputExitsTwoAndLeavesFilesAlone) {
  const fs::path p = scratch_->dir() / "bad.csv";
  const std::string bad = "problem,method,integrator,setting,max_residual\nwheel,baumgarte,rk4,step=0.001,-1\n";
  write(p, bad);
  Outcome o = cstab_cmd("gate --thresholds " + quote(p.string()) + " " + quote(dir_));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find(p.string() + ":2:5: max_residual: -1 is negative"), std::string::npos) << o.out;
  o = cstab_cmd("gate --update --thresholds " + quote(p.string()) + " " + quote(dir_));
  EXPECT_EQ(o.code, 2);
  EXPECT_EQ(slurp(p), bad);
  o = cstab_cmd("gate --thresholds " + quote(kCommitted) + " " + quote((scratch_->dir() / "nowhere").string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("no such results folder"), std::string::npos) << o.out;
  o = cstab_cmd("gate --thresholds " + quote(kCommitted) + " " + quote(scratch_->dir().string()));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("not a matrix results folder"), std::string::npos) << o.out;
  o = cstab_cmd("gate --thresholds " + quote((scratch_->dir() / "none.csv").string()) + " " + quote(dir_));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("cannot read"), std::string::npos) << o.out;
  o = cstab_cmd("gate --update --factor 0.5 --thresholds " + quote(kCommitted) + " " + quote(dir_));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.out.find("--factor: must be a finite number >= 1"), std::string::npos) << o.out;
}

// --------------------------------------------- the gate matrix (label gate)

// The committed thresholds on the gate matrix: what CI checks.
TEST(GateMatrix, CommittedThresholdsPassOnTheGateMatrix) {
  Scratch s("cstab_gate_matrix");
  const std::string dir = (s.dir() / "gate").string();
  const Outcome m = cstab_cmd("matrix " + quote(std::string(CSTAB_SOURCE_DIR) + "/matrices/gate.toml") + " --out " + quote(dir) +
                              " --jobs 2 --no-report");
  ASSERT_EQ(m.code, 0) << m.out;
  // The default thresholds (the committed file), strict: a case of the gate
  // matrix without a row fails too.
  const Outcome g = cstab_cmd("gate --strict " + quote(dir));
  std::printf("%s\n", g.out.c_str());
  EXPECT_EQ(g.code, 0) << g.out;
  EXPECT_NE(g.out.find(" 0 failed"), std::string::npos);
}

// Degraded configurations held to the thresholds of the configuration they
// degrade: a code change that made the good configuration behave like the
// degraded one would fail the gate, and for the expected check.
TEST(GateMatrix, DegradedConfigurationsFailForTheRightReason) {
  const ThresholdsFile committed = cstab::read_thresholds_file(kCommitted);
  auto column = [&](const std::string& name) {
    const auto it = std::find(committed.columns.begin(), committed.columns.end(), name);
    return it == committed.columns.end() ? -1 : int(it - committed.columns.begin());
  };
  struct Degradation {
    std::string problem, method, integrator, setting;      // the good case (committed row)
    std::string bad_method, bad_params, bad_setting;        // how it is degraded
    std::string failing_check;                              // the check that must fail
    std::string what;
    std::string t_end = "\"ref\"";                          // matrix value
  };
  const std::vector<Degradation> degradations = {
      // Over the wheel's 5 s the unstabilized drift peaks only slightly above
      // baumgarte's; what stabilization buys is the residual it leaves at the end.
      {"wheel", "baumgarte", "rk4", "step=0.001", "none", "", "step=0.001", "max_final_residual", "stabilization off"},
      {"wheel", "baumgarte", "rk4", "step=0.001", "baumgarte", "alpha=0;beta=0;gamma=0", "step=0.001",
       "max_final_residual", "gains set to 0"},
      {"wheel", "baumgarte", "rk4", "step=0.001", "baumgarte", "", "step=0.01", "max_ref_error", "10x step"},
      {"wheel", "projection", "rk4", "step=0.001", "projection", "tol=1", "step=0.001", "max_residual",
       "projection tolerance so loose it never projects"},
      {"ball", "projection", "rk4", "step=0.001", "none", "", "step=0.001", "max_residual", "projection off"},
      {"ball", "braun-goldfarb", "rk4", "step=0.001", "braun-goldfarb", "", "step=0.01", "max_residual", "10x step"},
      {"biped", "baumgarte", "rk4", "step=0.001", "none", "", "step=0.001", "max_final_residual",
       "stabilization off: the inconsistent start is never corrected"},
      // A stress case: from a start 1e-3 off the manifold, halved gains take
      // about twice as long to bring the residual back below 1e-10.
      {"wheel", "baumgarte", "rk8pd", "tol=1e-12;perturb=0.001", "baumgarte", "alpha=5;beta=5;gamma=5",
       "tol=1e-12;perturb=0.001", "max_recovery_time", "gains halved", "3"},
      // The methods of issue 17. generalized-alpha and ali3p are second
      // order: 10x the step is about 100x the reference error (measured
      // 2.9e-5 against slider-crank's bound 2.9e-6; 0.10 against the ball's
      // 1.0e-3). penalty with its factor 1e4 -> 1: a weak spring, not a
      // constraint (max residual 0.41 against the wheel's bound 6.0e-4).
      {"slider-crank", "generalized-alpha", "own", "step=0.001", "generalized-alpha", "", "step=0.01", "max_ref_error",
       "10x step"},
      {"ball", "ali3p", "own", "step=0.001", "ali3p", "", "step=0.01", "max_ref_error", "10x step"},
      {"wheel", "penalty", "rk4", "step=0.001", "penalty", "alpha=1", "step=0.001", "max_residual",
       "penalty factor 1e4 -> 1"},
      // rattle with a position-solve tolerance of 1e-4: max residual 2.0e-4
      // against the pendulum's bound 2e-11.
      {"pendulum", "rattle", "own", "step=0.001", "rattle", "tol=0.0001", "step=0.001", "max_residual",
       "position solve tolerance 1e-12 -> 1e-4"},
      // SUNDIALS' integrators (issue 18). CVODE with the projection inside
      // it, projection off: `none` on cvode-projection drifts to a max
      // residual of 3.1e-6 against car-axis's bound 5.4e-13; the tolerance
      // 1e-8 -> 1e-4 ends 0.04 from the reference (bound 4.1e-4). ARKODE's
      // Fehlberg 8 and CVODE's BDF at 1e-4 on the pendulum: 2.8e-3 and 0.17
      // (bounds 1.1e-6, 8.7e-4); the implicit ARK 5(4)8L on the stiff
      // flyball governor: 2.4e-3 (bound 1.1e-5).
      {"car-axis", "projection", "cvode-projection", "tol=1e-08", "none", "", "tol=1e-08", "max_residual",
       "projection off"},
      {"car-axis", "projection", "cvode-projection", "tol=1e-08", "projection", "", "tol=1e-04", "max_ref_error",
       "tolerance 1e-8 -> 1e-4"},
      {"pendulum", "baumgarte", "ark-erk-fehlberg8", "tol=1e-08", "baumgarte", "", "tol=1e-04", "max_ref_error",
       "tolerance 1e-8 -> 1e-4"},
      {"pendulum", "baumgarte", "cvode-bdf", "tol=1e-08", "baumgarte", "", "tol=1e-04", "max_ref_error",
       "tolerance 1e-8 -> 1e-4"},
      {"flyball-governor", "baumgarte", "ark-dirk-ark548", "tol=1e-08", "baumgarte", "", "tol=1e-04", "max_ref_error",
       "tolerance 1e-8 -> 1e-4"},
      // (Not here: ali3p with a loose tolerance (tol = 1e-3) stays on the
      // constraints, max residual 4.0e-11 on the ball: its projections, not
      // the tolerance, set the residual. Nor the slider crank with baumgarte
      // gains 0: it is *more* accurate over its 1 s than with the default
      // gains (residual 1.8e-13 vs 9.9e-13), so no accuracy gate can or
      // should flag it.)
  };
  std::string rows;
  std::set<int> emitted;
  std::string matrix = "[defaults]\nseries = false\n";
  // "tol=1e-12;perturb=0.001" -> "tol = 1e-12\nperturb = 0.001\n" (matrix keys)
  auto keys_of = [](const std::string& text) {
    std::string out;
    for (size_t start = 0; start < text.size();) {
      const size_t end = std::min(text.find(';', start), text.size());
      const std::string kv = text.substr(start, end - start);
      out += kv.substr(0, kv.find('=')) + " = " + kv.substr(kv.find('=') + 1) + "\n";
      start = end + 1;
    }
    return out;
  };
  int sweep = 0;
  for (const auto& d : degradations) {
    const cstab::ThresholdRow* good = nullptr;
    for (const auto& r : committed.rows)
      if (r.problem == d.problem && r.method == d.method && r.integrator == d.integrator && r.setting == d.setting &&
          r.params.empty() && r.sweep.empty())
        good = &r;
    ASSERT_NE(good, nullptr) << "no committed row for " << d.problem << " " << d.method;
    ASSERT_FALSE(std::isnan(good->*(&cstab::ThresholdRow::max_residual)));
    cstab::ThresholdRow bad = *good;
    bad.fields[column("method")] = d.bad_method;
    bad.fields[column("params")] = d.bad_params;
    bad.fields[column("setting")] = d.bad_setting;
    for (const cstab::ThresholdRow* r : {good, static_cast<const cstab::ThresholdRow*>(&bad)}) {
      if (r == good && !emitted.insert(good->line).second) continue;  // several degradations of one case
      for (size_t k = 0; k < r->fields.size(); ++k) rows += (k ? "," : "") + r->fields[k];
      rows += "\n";
    }
    matrix += "[[sweep]]\nname = \"d" + std::to_string(sweep++) + "\"\nproblems = [\"" + d.problem +
              "\"]\nmethods = [\"" + d.bad_method + "\"]\nintegrators = \"" + d.integrator + "\"\nt_end = " +
              d.t_end + "\n" + keys_of(d.bad_setting);
    std::string params = d.bad_params;
    if (!params.empty()) {
      params = keys_of(params);
      for (size_t pos = 0; (pos = params.find('\n', pos)) != std::string::npos && pos + 1 < params.size(); ++pos)
        params.insert(pos + 1, "param.");
      matrix += "param." + params;
    }
    matrix += "[[sweep]]\nname = \"g" + std::to_string(sweep++) + "\"\nproblems = [\"" + d.problem +
              "\"]\nmethods = [\"" + d.method + "\"]\nintegrators = \"" + d.integrator + "\"\nt_end = " +
              d.t_end + "\n" + keys_of(d.setting);
  }
  std::string header;
  for (size_t k = 0; k < committed.columns.size(); ++k) header += (k ? "," : "") + committed.columns[k];
  Scratch s("cstab_gate_degraded");
  write(s.dir() / "m.toml", matrix);
  write(s.dir() / "th.csv", header + "\n" + rows);
  const std::string dir = (s.dir() / "r").string();
  const Outcome m = cstab_cmd("matrix " + quote((s.dir() / "m.toml").string()) + " --out " + quote(dir) + " --jobs 2 --no-report");
  ASSERT_EQ(m.code, 0) << m.out << "\n" << matrix;
  const std::string csv = (s.dir() / "gate.csv").string();
  const Outcome g = cstab_cmd("gate --thresholds " + quote((s.dir() / "th.csv").string()) + " --csv " + quote(csv) +
                              " " + quote(dir));
  std::printf("%s\n", g.out.c_str());
  EXPECT_EQ(g.code, 1) << g.out;
  const cstab::CsvTable t = cstab::read_csv(csv);
  // Good rows pass every check; degraded rows are honest runs (status ok)
  // that fail the expected bound.
  for (const auto& d : degradations) {
    const std::string good_label = d.problem + " " + d.method + " " + d.integrator + " " + d.setting;
    std::string bad_label = d.problem + " " + d.bad_method + " " + d.integrator + " " + d.bad_setting;
    if (!d.bad_params.empty()) bad_label += " [" + d.bad_params + "]";
    bool saw_good = false, saw_bad_status = false, saw_bad_failure = false;
    for (size_t i = 0; i < t.rows.size(); ++i) {
      const std::string& label = t.get(i, "case");
      if (label == good_label) {
        saw_good = true;
        EXPECT_EQ(t.get(i, "result"), "pass") << good_label << " " << t.get(i, "check");
      } else if (label == bad_label) {
        if (t.get(i, "check") == "status") {
          saw_bad_status = true;
          EXPECT_EQ(t.get(i, "result"), "pass") << bad_label << " did not run to the end";
        }
        if (t.get(i, "check") == d.failing_check) {
          saw_bad_failure = true;
          EXPECT_EQ(t.get(i, "result"), "fail") << bad_label << " (" << d.what << ") passed " << d.failing_check;
        }
      }
    }
    EXPECT_TRUE(saw_good && saw_bad_status && saw_bad_failure) << good_label << " / " << bad_label;
  }
}

}  // namespace

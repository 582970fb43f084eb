// External cases of a matrix (key `external`): an outside program's
// trajectory scored like any case. cstab itself, run as the outside
// program, must score to what the same run gives as a built-in case; a
// program that fails, hangs, writes nothing, writes garbage or stops early
// is a recorded result; a malformed external sweep is bad input (exit 2).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "io/csv.hpp"
#include "matrix/results.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

namespace fs = std::filesystem;
using testing::Scratch;
using testing::contains;
using testing::cstab_cmd;
using testing::quote;

fs::path write(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

// The rows of DIR/summary.csv keyed by method/problem/step.
std::map<std::string, std::map<std::string, std::string>> rows_of(const fs::path& summary) {
  const CsvTable t = read_csv(summary.string());
  std::map<std::string, std::map<std::string, std::string>> out;
  for (const auto& r : t.rows) {
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < t.header.size() && i < r.size(); ++i) row[t.header[i]] = r[i];
    out[row["method"] + "/" + row["problem"] + "/" + row["step"]] = row;
  }
  return out;
}

TEST(ExternalCase, CstabRunAsAnOutsideProgramScoresLikeTheBuiltInCase) {
  Scratch s;
  const std::string run = quote(CSTAB_BINARY) +
                          " run --problem {problem} --method baumgarte --integrator rk4 --step {step} --t-end {t_end}"
                          " --sample-every 1e-300 --out {out}.d && mv {out}.d/series.csv {out} && rm -r {out}.d";
  std::string escaped;  // a TOML basic string
  for (char ch : run) escaped += ch == '"' || ch == '\\' ? std::string("\\") + ch : std::string(1, ch);
  const fs::path file = write(s.dir() / "m.toml",
                              "[[sweep]]\nname = \"outside\"\nproblems = [\"pendulum\", \"slider-crank\"]\n"
                              "external = \"" + escaped + "\"\nexternal_name = \"cstab-rk4\"\n"
                              "step = [1e-2, 5e-3]\nt_end = 2\n"
                              "[[sweep]]\nname = \"inside\"\nproblems = [\"pendulum\", \"slider-crank\"]\n"
                              "methods = \"baumgarte\"\nintegrators = \"rk4\"\nstep = [1e-2, 5e-3]\nt_end = 2\n");
  const auto o = cstab_cmd("matrix " + quote(file.string()) + " --no-report --jobs 2 --out " +
                           quote((s.dir() / "out").string()));
  ASSERT_EQ(o.code, 0) << o.out;
  const auto rows = rows_of(s.dir() / "out" / "summary.csv");
  ASSERT_EQ(rows.size(), 8u);
  for (const char* problem : {"pendulum", "slider-crank"})
    for (const char* step : {"0.01", "0.005"}) {
      SCOPED_TRACE(std::string(problem) + " " + step);
      const auto& outside = rows.at(std::string("cstab-rk4/") + problem + "/" + step);
      const auto& inside = rows.at(std::string("baumgarte/") + problem + "/" + step);
      EXPECT_EQ(outside.at("status"), "ok") << outside.at("reason");
      EXPECT_EQ(outside.at("integrator"), "external");
      for (const char* column : {"max_residual", "final_residual", "max_energy_drift", "final_energy_drift",
                                 "t_reached", "steps", "initial_residual"})
        EXPECT_EQ(outside.at(column), inside.at(column)) << column;
      EXPECT_GT(std::stod(outside.at("wall_seconds")), 0);  // the process's time
    }
  // Cached like any case: the second run reruns nothing.
  const auto again = cstab_cmd("matrix " + quote(file.string()) + " --no-report --out " +
                               quote((s.dir() / "out").string()));
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_TRUE(contains(again.out, "8 cached")) << again.out;

  // The report draws the outside program as another engine: its curve after
  // cstab's under the key's heading (the picture's ncstab), and an "Other
  // engines" table per problem with the engine named by external_name's
  // first word (no reference time within t = 2 here: its cells say "not
  // reached").
  const auto rep = cstab_cmd("report --no-plots " + quote((s.dir() / "out").string()));
  ASSERT_EQ(rep.code, 0) << rep.out;
  std::ifstream html_in(s.dir() / "out" / "report.html");
  const std::string html((std::istreambuf_iterator<char>(html_in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(contains(html, "<h3>Other engines</h3>"));
  EXPECT_TRUE(contains(html, "</td><td>cstab</td><td>")) << "the engine 'cstab' (of cstab-rk4)";
  std::ifstream replot_in(s.dir() / "out" / "plots" / "replot.sh");
  const std::string replot((std::istreambuf_iterator<char>(replot_in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(contains(replot, "ncstab=1")) << "one cstab curve (baumgarte/rk4) before the external one";
}

TEST(ExternalCase, AFailingHangingOrSilentProgramIsARecordedResult) {
  Scratch s;
  const auto sweep = [](const std::string& name, const std::string& command, const std::string& extra = "") {
    return "[[sweep]]\nname = \"" + name + "\"\nproblems = \"pendulum\"\nexternal = \"" + command +
           "\"\nexternal_name = \"" + name + "\"\nt_end = 1\n" + extra;
  };
  const fs::path file = write(
      s.dir() / "m.toml",
      sweep("exits-3", "echo boom >&2; exit 3 # {out}") + sweep("hangs", "sleep 60 # {out}", "timeout = 2\n") +
          sweep("writes-nothing", "true # {out}") + sweep("writes-garbage", "echo 'a;b' > {out}") +
          sweep("stops-early", "printf 't,x,y,xdot,ydot\\\\n0,1,0,0,0\\\\n0.5,1,0,0,0\\\\n' > {out}") +
          sweep("killed", "kill -9 $$ # {out}"));
  const auto start = std::chrono::steady_clock::now();
  const auto o = cstab_cmd("matrix " + quote(file.string()) + " --no-report --jobs 2 --out " +
                           quote((s.dir() / "out").string()));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_LT(seconds, 30);  // the sleeper was stopped at its timeout, not after 60 s
  const auto rows = rows_of(s.dir() / "out" / "summary.csv");
  auto row = [&](const std::string& name) { return rows.at(name + "/pendulum/"); };
  EXPECT_EQ(row("exits-3").at("status"), "failed");
  EXPECT_TRUE(contains(row("exits-3").at("reason"), "exited with code 3")) << row("exits-3").at("reason");
  EXPECT_TRUE(contains(row("exits-3").at("reason"), "boom")) << row("exits-3").at("reason");
  EXPECT_EQ(row("hangs").at("status"), "timeout") << row("hangs").at("reason");
  EXPECT_EQ(row("writes-nothing").at("status"), "failed");
  EXPECT_TRUE(contains(row("writes-nothing").at("reason"), "no such file")) << row("writes-nothing").at("reason");
  EXPECT_EQ(row("writes-garbage").at("status"), "failed");
  EXPECT_TRUE(contains(row("writes-garbage").at("reason"), "external trajectory")) << row("writes-garbage").at("reason");
  EXPECT_EQ(row("stops-early").at("status"), "failed");
  EXPECT_TRUE(contains(row("stops-early").at("reason"), "ends at t = 0.5")) << row("stops-early").at("reason");
  EXPECT_EQ(row("killed").at("status"), "failed");
  EXPECT_TRUE(contains(row("killed").at("reason"), "signal 9")) << row("killed").at("reason");
  // No trajectory or output log is left in a case folder.
  for (const auto& e : fs::recursive_directory_iterator(s.dir() / "out")) {
    EXPECT_NE(e.path().filename(), "external-trajectory.csv");
    EXPECT_NE(e.path().filename(), "external-output.log");
  }
}

TEST(ExternalCase, AMalformedExternalSweepIsBadInput) {
  struct Bad {
    std::string body, message;
  };
  const std::string head = "[[sweep]]\nproblems = \"pendulum\"\n";
  for (const Bad& b : std::vector<Bad>{
           {"external = \"true {out}\"\n", "needs 'external_name'"},
           {"external_name = \"x\"\n", "given without 'external'"},
           {"external = \"true\"\nexternal_name = \"x\"\n", "must write its trajectory to {out}"},
           {"external = \"true {out} {speed}\"\nexternal_name = \"x\"\n", "unknown placeholder '{speed}'"},
           {"external = \"true {out} {step}\"\nexternal_name = \"x\"\n", "{step} used but the sweep has no 'step'"},
           {"external = \"true {out}\"\nexternal_name = \"x\"\nmethods = \"none\"\n", "methods: not for an external"},
           {"external = \"true {out}\"\nexternal_name = \"x\"\nintegrators = \"rk4\"\n", "integrators: not for an"},
           {"external = \"true {out}\"\nexternal_name = \"baumgarte\"\n", "a built-in method's name"},
           {"external = \"true {out}\"\nexternal_name = \"a b\"\n", "external_name: must be non-empty"},
           {"external = \"true {out}\"\nexternal_name = \"x\"\nparam.lambda = 1\n", "param.*: not for an external"},
           {"external = \"true {out}\"\nexternal_name = \"x\"\ntune = 5\n", "tune: not for an external"},
       }) {
    SCOPED_TRACE(b.message);
    Scratch s;
    const fs::path file = write(s.dir() / "m.toml", head + b.body);
    const auto o = cstab_cmd("matrix " + quote(file.string()) + " --out " + quote((s.dir() / "out").string()));
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_TRUE(contains(o.out, b.message)) << o.out;
    EXPECT_TRUE(contains(o.out, "m.toml:")) << o.out;
    EXPECT_FALSE(fs::exists(s.dir() / "out"));
  }
}

}  // namespace
}  // namespace cstab

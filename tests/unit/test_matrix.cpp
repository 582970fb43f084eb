// The benchmark matrix: the file is TOML (toml++), parser errors name
// file:line:column, expansion is
// deterministic, shards partition the cases, two shards run through GNU
// parallel and merged equal one single-process run (timing columns aside),
// an unchanged re-run runs nothing, and the report opens in a real browser
// with every picture loaded.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "cli/matrix_commands.hpp"
#include "core/format.hpp"
#include "harness/tune.hpp"
#include "matrix/matrix.hpp"
#include "tests/support/test_util.hpp"
#include "methods/pair.hpp"
#include "problems/registry.hpp"

namespace cstab {
namespace {

namespace fs = std::filesystem;

using testing::registry_catalog;
// The message of the MatrixError that parsing + expanding `text` throws.
std::string error_of(const std::string& text) { return testing::matrix_error_of(text); }

const char* kSweepHead = "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\", \"minimal\"]\n";

TEST(MatrixParse, ErrorsNameFileLineAndColumn) {
  // Syntax.
  EXPECT_EQ(error_of("[[sweep]]\nstep = [1e-3, abc]\n").substr(0, 13), "m.toml:2:15: ") << error_of("[[sweep]]\nstep = [1e-3, abc]\n");
  EXPECT_NE(error_of("[[sweep]]\nstep = [1e-3, abc]\n").find("strings are quoted"), std::string::npos);
  // toml++ places these at the end of the line or file where it noticed them.
  EXPECT_EQ(error_of("[[sweep]]\nname = \"open\n").substr(0, 13), "m.toml:2:13: ");
  EXPECT_NE(error_of("[[sweep]]\nname = \"open\n").find("unterminated string"), std::string::npos);
  EXPECT_EQ(error_of("[[sweep]]\nstep = [1e-3,\n  2e-3\n").substr(0, 12), "m.toml:3:8: ");
  EXPECT_NE(error_of("[[sweep]]\nstep = [1e-3,\n  2e-3\n").find("missing ']'"), std::string::npos);
  EXPECT_EQ(error_of("[sweep]\n").substr(0, 12), "m.toml:1:2: ");
  EXPECT_NE(error_of("[sweep]\n").find("[[sweep]]"), std::string::npos);
  EXPECT_EQ(error_of("step = 1\n").substr(0, 12), "m.toml:1:1: ");
  EXPECT_EQ(error_of("[[sweep]]\nrepeats = 2 3\n").substr(0, 13), "m.toml:2:13: ");
  EXPECT_NE(error_of("[[sweep]]\nt_end = 1\nt_end = 2\n").find("m.toml:3:9: "), std::string::npos);
  EXPECT_NE(error_of("[[sweep]]\nt_end = 1\nt_end = 2\n").find("cannot redefine existing integer 't_end'"),
            std::string::npos);
  EXPECT_NE(error_of("[defaults]\n[defaults]\n").find("m.toml:2:1: "), std::string::npos);
  EXPECT_NE(error_of("[[sweep]]\nname = \"a\\q\"\n").find("m.toml:2:11: "), std::string::npos);
  // What TOML allows but a matrix file cannot hold.
  EXPECT_EQ(error_of("[foo]\n"), "m.toml:1:2: unknown section 'foo' (known: [defaults], [[sweep]])");
  EXPECT_EQ(error_of("[[defaults]]\n").substr(0, 12), "m.toml:1:3: ");
  EXPECT_EQ(error_of("a.b = 1\n"), "m.toml:1:1: key outside a section: start the file with [defaults] or [[sweep]]");
  EXPECT_EQ(error_of("[[sweep]]\nstep = [[1e-3]]\n"), "m.toml:2:9: step: nested arrays are not supported");
  EXPECT_NE(error_of("[[sweep]]\nstep = 1979-05-27\n").find("m.toml:2:8: step: dates and times"), std::string::npos);
  EXPECT_NE(error_of("[[sweep]]\nstep = [{a = 1}]\n").find("m.toml:2:9: step: a table is not a value"),
            std::string::npos);
  EXPECT_EQ(error_of("[[sweep]]\n[sweep.x]\n"), "m.toml:2:8: 'x': empty table");
  EXPECT_NE(error_of("[[sweep]]\n\"param.lambda\" = 1\n").find("m.toml:2:1: key 'param.lambda': a key part is"),
            std::string::npos);
  // Meaning.
  const std::string unknown_key = error_of(std::string(kSweepHead) + "integrators = [\"rk4\"]\nstep = 1e-3\n  problem = \"x\"\n");
  EXPECT_EQ(unknown_key.substr(0, 12), "m.toml:6:3: ") << unknown_key;
  EXPECT_NE(unknown_key.find("did you mean 'problems'"), std::string::npos) << unknown_key;
  const std::string unknown_problem = error_of("[[sweep]]\nproblems = [\"wheel\", \"wheeel\"]\nmethods = \"all\"\n"
                                               "integrators = [\"rk4\"]\nstep = 1e-3\n");
  EXPECT_EQ(unknown_problem.substr(0, 13), "m.toml:2:22: ") << unknown_problem;
  EXPECT_NE(unknown_problem.find("did you mean 'wheel'"), std::string::npos) << unknown_problem;
  const std::string no_step = error_of(std::string(kSweepHead) + "integrators = [\"rk8pd\", \"rk4\"]\ntol = 1e-8\n");
  EXPECT_EQ(no_step.substr(0, 12), "m.toml:4:1: ") << no_step;
  EXPECT_NE(no_step.find("'rk4' is fixed-step"), std::string::npos) << no_step;
  const std::string bad_t_end =
      error_of(std::string(kSweepHead) + "integrators = \"rk4\"\nstep = 1e-3\nt_end = [1, \"later\"]\n");
  EXPECT_EQ(bad_t_end.substr(0, 13), "m.toml:6:13: ") << bad_t_end;
  const std::string bad_param = error_of(std::string(kSweepHead) +
                                         "integrators = \"rk4\"\nstep = 1e-3\nparam.pesterev.lambdaa = 5\n");
  EXPECT_EQ(bad_param.substr(0, 12), "m.toml:6:1: ") << bad_param;
  EXPECT_NE(bad_param.find("no parameter 'lambdaa'"), std::string::npos) << bad_param;
}

// Issue 9 audit: every inconsistency is a MatrixError at the value that
// causes it (or the sweep header when the sweep as a whole is impossible).
TEST(MatrixExpand, RejectsImpossibleSettingsAtTheirLocation) {
  const std::string head = std::string(kSweepHead) + "integrators = \"rk4\"\nstep = 1e-3\nt_end = 1\n";
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      // text, location, message part
      {head + "param.lambda = [100, -5]\n", "m.toml:7:22: ", "must be > 0 for method 'pesterev'"},
      {head + "param.pesterev.lambda = 0\n", "m.toml:7:25: ", "must be > 0"},
      {head + "formulations = [\"lagrange\"]\n", "m.toml:7:17: ", "unknown formulation 'lagrange'"},
      {head + "times = [0.5, 2]\n", "m.toml:7:15: ", "times: 2 is beyond t_end 1"},
      {head + "times = -1\n", "m.toml:7:9: ", "must be > 0"},
      {head + "ref_time = 2\n", "m.toml:7:12: ", "ref_time: 2 is beyond t_end 1"},
      {head + "observe_every = 1e300\n", "m.toml:7:17: ", "observe_every"},  // was an int overflow
      {head + "repeats = 1.5\n", "m.toml:7:11: ", "repeats"},
      {head + "series = 1\n", "m.toml:7:10: ", "expected true/false"},
      {head + "blowup = nan\n", "m.toml:7:10: ", "'nan' is not a finite number"},
      {head + "timeout = inf\n", "m.toml:7:11: ", "'inf' is not a finite number"},
      {head + "timeout = -inf\n", "m.toml:7:11: ", "'-inf' is not a finite number"},
      {head + "timeout = 1e999\n", "m.toml:7:16: ", "'1e999' could not be interpreted"},  // toml++: out of range
      {head + "timeout = +inf\n", "m.toml:7:11: ", "'+inf' is not a finite number"},
      {head + "param.lambda = [100, nan]\n", "m.toml:7:22: ", "'nan' is not a finite number"},
      {head + "tune = 1\n", "m.toml:7:8: ", "tune: must be an integer in [2, 25]"},
      {head + "tune = 2.5\n", "m.toml:7:8: ", "tune: must be an integer in [2, 25]"},
      {head + "tune = 26\n", "m.toml:7:8: ", "tune: must be an integer in [2, 25]"},
      {head + "tune = -3\n", "m.toml:7:8: ", "tune: must be an integer in [2, 25]"},
      {head + "tune = 5\nparam.lambda = [10, 100]\n", "m.toml:8:1: ",
       "param.lambda: tune sweeps pesterev's gain 'lambda' itself"},
      {"[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"ida-ggl\"]\nintegrators = \"rk4\"\nstep = 1e-3\n",
       "m.toml:1:1: ", "expands to no case"},
      {"[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\nintegrators = \"ida\"\ntol = 1e-6\n",
       "m.toml:1:1: ", "'ida' needs a DAE method"},
      {"[[sweep]]\nproblems = [\"biped\"]\nmethods = [\"minimal\"]\nintegrators = \"rk4\"\nstep = 1e-3\n",
       "m.toml:1:1: ", "minimal does not apply to biped"},
      {"[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\"]\nintegrators = \"rk4\"\nstep = 1\nt_end = 0.5\n",
       "m.toml:1:1: ", "larger than t_end"},
      {"", "m.toml:1:1: ", "no [[sweep]]"},
      {"# only a comment\n[defaults]\nrepeats = 2\n", "m.toml:1:1: ", "no [[sweep]]"},
      {"[[sweep]]\nproblems = \"all\"\nmethods = \"all\"\nintegrators = \"rk4\"\nstep = [1,2,3,4,5,6,7,8,9,10]\n"
       "t_end = 100\nparam.alpha = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40]\n"
       "param.beta = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40]\n"
       "param.gamma = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40]\n",
       "m.toml:1:1: ", "more than 100000 cases"},
  };
  for (const auto& [text, where, what] : cases) {
    SCOPED_TRACE(text);
    const std::string e = error_of(text);
    EXPECT_EQ(e.substr(0, where.size()), where) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
  }
}

// DAE methods meet only the DAE integrator, and the other way round: with
// methods = "all" the impossible pairs are skipped (not run as "invalid").
TEST(MatrixExpand, DaeMethodsMeetOnlyTheDaeIntegrator) {
  const auto ex = expand_matrix(parse_matrix("[[sweep]]\nproblems = [\"wheel\"]\nmethods = \"all\"\n"
                                             "integrators = [\"rk4\", \"ida\"]\nstep = 1e-3\ntol = 1e-6\nt_end = 1\n",
                                             "m.toml"),
                                registry_catalog());
  std::set<std::string> with_ida, with_rk4;
  for (const auto& c : ex.cases) (c.entry.integrator == "ida" ? with_ida : with_rk4).insert(c.entry.method);
  EXPECT_EQ(with_ida, (std::set<std::string>{"ida-index1", "ida-ggl"}));
  EXPECT_FALSE(with_rk4.count("ida-ggl"));
  EXPECT_FALSE(with_rk4.count("ida-index1"));
  EXPECT_TRUE(with_rk4.count("pesterev"));
}

TEST(MatrixParse, AFolderIsNotAMatrixFile) {
  try {
    read_matrix_file("/tmp");
    ADD_FAILURE() << "read a folder";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("/tmp: is a folder"), std::string::npos) << e.what();
  }
}

TEST(MatrixParse, ReadsToml) {
  const MatrixFile f = parse_matrix(
      "# comment\n[defaults]\nrepeats = 2 # trailing\n\n[[sweep]]\nname = 'literal'\n"
      "step = [\n  1e-3,  # first\n  5_000e-7,\n]\nparam.pesterev.lambda = 1500\nseries = false\n",
      "f.toml");
  ASSERT_EQ(f.sections.size(), 2u);
  EXPECT_EQ(f.sections[0].kind, "defaults");
  const auto& e = f.sections[1].entries;
  ASSERT_EQ(e.size(), 4u);
  EXPECT_EQ(e[0].value.text, "literal");
  ASSERT_EQ(e[1].value.items.size(), 2u);
  EXPECT_DOUBLE_EQ(e[1].value.items[1].number, 5e-4);
  EXPECT_EQ(e[1].value.items[1].where.line, 9);
  EXPECT_EQ(e[2].key, "param.pesterev.lambda");
  EXPECT_FALSE(e[3].value.boolean);
}

// Every number form TOML defines, and no other (the hand-written parser
// before toml++ took "1__0e-3", ".5" and "00012").
TEST(MatrixParse, NumbersAreTomlNumbers) {
  const MatrixFile f = parse_matrix(
      "[[sweep]]\nstep = [1_000, 1e-3, +5, -0.5e+2, 5E3, 0x1f, 0o17, 0b101, 1_0.2_5, 3.0]\n", "n.toml");
  ASSERT_EQ(f.sections.size(), 1u);
  const auto& items = f.sections[0].entries.at(0).value.items;
  const std::vector<double> want = {1000, 1e-3, 5, -50, 5000, 31, 15, 5, 10.25, 3};
  ASSERT_EQ(items.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(items[i].kind, MatrixValue::Kind::kNumber) << i;
    EXPECT_DOUBLE_EQ(items[i].number, want[i]) << i;
  }
  EXPECT_EQ(items[0].text, "1_000");  // messages quote the source
  EXPECT_EQ(items[2].text, "+5");
  EXPECT_EQ(items[5].where.column, 40);
  const std::string head = "[[sweep]]\nproblems = [\"wheel\"]\nstep = ";
  for (const auto& [bad, where] : std::vector<std::pair<std::string, std::string>>{
           {"1__0e-3", "m.toml:3:10: "}, {".5", "m.toml:3:8: "}, {"00012", "m.toml:3:13: "},
           {"[1e-3, 1.]", "m.toml:3:17: "}, {"1e", "m.toml:3:10: "}, {"0x", "m.toml:3:10: "}}) {
    SCOPED_TRACE(bad);
    EXPECT_EQ(error_of(head + bad + "\n").substr(0, where.size()), where) << error_of(head + bad + "\n");
  }
}

// A UTF-8 byte order mark at the start is allowed and not counted in columns.
TEST(MatrixParse, AcceptsAByteOrderMark) {
  const auto plain = expand_matrix(parse_matrix(kSweepHead + std::string("integrators = \"rk4\"\nstep = 1e-3\n"),
                                                "m.toml"),
                                   registry_catalog());
  const auto bom = expand_matrix(
      parse_matrix("\xEF\xBB\xBF" + std::string(kSweepHead) + "integrators = \"rk4\"\nstep = 1e-3\n", "m.toml"),
      registry_catalog());
  ASSERT_EQ(bom.cases.size(), plain.cases.size());
  ASSERT_FALSE(bom.cases.empty());
  for (size_t i = 0; i < bom.cases.size(); ++i) EXPECT_EQ(bom.cases[i].entry.id, plain.cases[i].entry.id);
  EXPECT_EQ(error_of("\xEF\xBB\xBF[sweep]\n").substr(0, 12), "m.toml:1:2: ");
  EXPECT_EQ(error_of("\xEF\xBB\xBF[[sweep]]\nstep = abc\n").substr(0, 12), "m.toml:2:8: ");
  // A second one is not a BOM but a stray character.
  EXPECT_EQ(error_of("\xEF\xBB\xBF\xEF\xBB\xBF[[sweep]]\n").substr(0, 9), "m.toml:1:");
}

// Non-ASCII characters: in strings and comments as TOML allows; elsewhere
// refused before toml++ 3.3 sees them (it has undefined behaviour there).
TEST(MatrixParse, NonAsciiOnlyInStringsAndComments) {
  const MatrixFile f = parse_matrix("# Straße\n[[sweep]]\nname = \"Zürich\"  # é\nproblems = 'ü'\nx = \"\"\"ß\n\"\"\"\n",
                                    "u.toml");
  ASSERT_EQ(f.sections.at(0).entries.size(), 3u);
  EXPECT_EQ(f.sections[0].entries[0].value.text, "Zürich");
  EXPECT_EQ(f.sections[0].entries[2].value.text, "ß\n");
  EXPECT_NE(error_of("[[sweep]]\nname = \"Zürich\"\n\"é\" = 1\n").find("m.toml:3:1: key 'é': a key part is"),
            std::string::npos);
  const std::string outside = "non-ASCII character outside a string or comment";
  for (const auto& [text, where] : std::vector<std::pair<std::string, std::string>>{
           {"[[sweep]]\né = 1\n", "m.toml:2:1: "},
           {"[[sweep]]\nstep = 1é\n", "m.toml:2:9: "},
           {"[[sweep]]\nname = \"ü\" é\n", "m.toml:2:12: "},
           {"[[sweep]]\nstep = [1, \xC2\xA0 2]\n", "m.toml:2:12: "},
           {"[[sweep]]\nstep = [0xZ0\"a\xD2\x95" "b\"]\n", "m.toml:2:15: "}}) {  // a quote in a bare word
    SCOPED_TRACE(text);
    EXPECT_EQ(error_of(text).substr(0, where.size()), where) << error_of(text);
    EXPECT_NE(error_of(text).find(outside), std::string::npos) << error_of(text);
  }
  // Positions and source text after non-ASCII characters on the same line.
  const MatrixFile g = parse_matrix("[[sweep]]\nx = [\"ü\", \"éé\", 1_0, 2]  # ß\n", "u.toml");
  const auto& items = g.sections.at(0).entries.at(0).value.items;
  ASSERT_EQ(items.size(), 4u);
  EXPECT_EQ(items[2].text, "1_0");
  EXPECT_EQ(items[2].where.str(), "u.toml:2:17");
  EXPECT_EQ(items[3].text, "2");
  EXPECT_EQ(items[1].where.str(), "u.toml:2:11");
  const MatrixFile h = parse_matrix("[[sweep]]\nparam = { s = \"ü\", x.y = 1 }\n", "u.toml");
  ASSERT_EQ(h.sections.at(0).entries.size(), 2u);
  EXPECT_EQ(h.sections[0].entries[1].key, "param.x.y");
  EXPECT_EQ(h.sections[0].entries[1].where.str(), "u.toml:2:20");
  const std::string after_backslash = error_of("[[sweep]]\nname = \"\"\"a\\\n   \xC2\xA7\"\"\"\n");
  EXPECT_EQ(after_backslash.substr(0, 12), "m.toml:3:4: ") << after_backslash;
  EXPECT_NE(after_backslash.find("line-ending backslash"), std::string::npos) << after_backslash;
}

// A dotted key of very many parts is refused before toml++ 3.3 (which
// recurses once per part) overflows the stack; numbers and strings do not count.
TEST(MatrixParse, DottedKeyOfManyPartsIsAnErrorNotACrash) {
  std::string key = "p";
  for (int i = 0; i < 200000; ++i) key += ".p";
  const std::string e = error_of("[[sweep]]\n" + key + " = 1\n");
  EXPECT_EQ(e.substr(0, 14), "m.toml:2:130: ") << e.substr(0, 200);
  EXPECT_NE(e.find("more than 64 dots in a dotted key"), std::string::npos) << e.substr(0, 200);
  std::string many = "[[sweep]]\nstep = [";
  for (int i = 0; i < 200; ++i) many += "1.5, ";
  many += "2.5]\nname = \"" + std::string(100, '.') + "\"\n";
  const MatrixFile f = parse_matrix(many, "m.toml");
  EXPECT_EQ(f.sections.at(0).entries.at(0).value.items.size(), 201u);
  EXPECT_EQ(f.sections[0].entries.at(1).value.text, std::string(100, '.'));
}

// The same parameter keys in every TOML spelling give the same cases; a
// key's location is where it starts on its line.
TEST(MatrixParse, DottedKeysInAnyTomlSpelling) {
  const std::string head = std::string(kSweepHead) + "integrators = \"rk4\"\nstep = 1e-3\nt_end = 1\n";
  const auto cases = [&](const std::string& text) {
    std::vector<std::string> out;
    for (const auto& c : expand_matrix(parse_matrix(text, "m.toml"), registry_catalog()).cases)
      out.push_back(c.entry.id + " " + c.entry.label());
    return out;
  };
  const auto dotted = cases(head + "param.pesterev.lambda = [10, 20]\n");
  ASSERT_EQ(dotted.size(), 2u + 1u) << dotted.size();  // pesterev x 2 lambdas, minimal once
  EXPECT_NE(dotted[1].find("lambda=20"), std::string::npos) << dotted[1];
  EXPECT_EQ(cases(head + "param = { pesterev = { lambda = [10, 20] } }\n"), dotted);
  EXPECT_EQ(cases(head + "param = { pesterev.lambda = [10, 20] }\n"), dotted);
  EXPECT_EQ(cases(head + "  param . \"pesterev\".lambda = [10, 20]\n"), dotted);
  EXPECT_EQ(cases("[defaults.param.pesterev]\nlambda = [10, 20]\n" + head), dotted);
  EXPECT_EQ(cases(head + "param.lambda = [10, 20]\n"), dotted);  // minimal declares no lambda
  const MatrixFile f = parse_matrix("[[sweep]]\n  param.x.y = 1\n  param.z = { w = 2 }\n", "m.toml");
  ASSERT_EQ(f.sections.at(0).entries.size(), 2u);
  EXPECT_EQ(f.sections[0].entries[0].key, "param.x.y");
  EXPECT_EQ(f.sections[0].entries[0].where.str(), "m.toml:2:3");
  EXPECT_EQ(f.sections[0].entries[1].key, "param.z.w");
  EXPECT_EQ(f.sections[0].entries[1].where.str(), "m.toml:3:15");
}

const char* kSmall = R"([defaults]
problems = ["wheel"]
methods = ["pesterev", "minimal"]
t_end = 1
ref_time = 1

[[sweep]]
name = "fixed"
integrators = ["rk4", "adams"]
step = [1e-3, 5e-4]
param.lambda = [500, 1500]

[[sweep]]
name = "adaptive"
integrators = "rk8pd"
tol = [1e-6, 1e-8]
repeats = 2
)";

TEST(MatrixExpand, IsDeterministicAndAppliesParametersOnlyWhereDeclared) {
  const auto a = expand_matrix(parse_matrix(kSmall, "s.toml"), registry_catalog());
  const auto b = expand_matrix(parse_matrix(kSmall, "s.toml"), registry_catalog());
  // fixed: pesterev 2 integrators x 2 steps x 2 lambdas + minimal 2 x 2; adaptive: 2 methods x 2 tols.
  ASSERT_EQ(a.cases.size(), 8u + 4u + 4u);
  std::set<std::string> ids;
  for (size_t i = 0; i < a.cases.size(); ++i) {
    EXPECT_EQ(a.cases[i].entry.id, b.cases[i].entry.id);
    EXPECT_EQ(a.cases[i].entry.index, i);
    ids.insert(a.cases[i].entry.id);
    if (a.cases[i].entry.method == "minimal") {
      EXPECT_EQ(a.cases[i].entry.params, "");
    }
    if (a.cases[i].entry.method == "pesterev" && a.cases[i].entry.sweep == "fixed") {
      EXPECT_EQ(a.cases[i].entry.params.rfind("lambda=", 0), 0u);
    }
  }
  EXPECT_EQ(ids.size(), a.cases.size());
  EXPECT_EQ(a.cases[0].entry.label(), "wheel pesterev rk4 step=0.001 t_end=1 lambda=500");
  EXPECT_EQ(a.cases.back().entry.label(), "wheel minimal rk8pd tol=1e-08 t_end=1 x2");
  // The id depends on the configuration only: a case keeps it in another matrix.
  const auto one = expand_matrix(parse_matrix("[[sweep]]\nname = \"other\"\nproblems = \"wheel\"\nmethods = \"minimal\"\n"
                                              "integrators = \"rk8pd\"\ntol = 1e-8\nt_end = 1\nref_time = 1\nrepeats = 2\n",
                                              "o.toml"),
                                 registry_catalog());
  ASSERT_EQ(one.cases.size(), 1u);
  EXPECT_EQ(one.cases[0].entry.id, a.cases.back().entry.id);
}

// Key `tune = N`: each method's declared gain at N values (tune_gains: 3
// decades around the default), its tied parameters alike, as a curve
// "... tuned" beside the default-gain cases; a method without a gain runs
// its defaults only.
TEST(MatrixExpand, TuneSweepsEachMethodsGainBesideItsDefaults) {
  const auto x = expand_matrix(parse_matrix("[[sweep]]\nproblems = [\"wheel\"]\n"
                                            "methods = [\"pesterev\", \"baumgarte\", \"minimal\"]\n"
                                            "integrators = \"rk4\"\nstep = [1e-2, 1e-3]\nt_end = 1\ntune = 4\n",
                                            "t.toml"),
                               registry_catalog());
  const std::vector<double> lambdas = tune_gains(*find_gain(all_methods()[size_t(method_index("pesterev"))].params), 4);
  const std::vector<double> alphas = tune_gains(*find_gain(all_methods()[size_t(method_index("baumgarte"))].params), 4);
  ASSERT_EQ(lambdas.size(), 4u);
  ASSERT_EQ(alphas.size(), 4u);
  // 3 decades around the default, log-spaced: the ends are default x 10^-1.5 and x 10^1.5.
  EXPECT_NEAR(lambdas.front(), 6 * std::pow(10, -1.5), 0.01 * lambdas.front());
  EXPECT_NEAR(lambdas.back(), 6 * std::pow(10, 1.5), 0.01 * lambdas.back());
  // (1 default + 4 gains) x 2 steps for the two methods with a gain, 2 for minimal.
  ASSERT_EQ(x.cases.size(), 2u * 5u * 2u + 2u);
  std::map<std::string, std::set<std::string>> params_of;
  for (const auto& c : x.cases) {
    const CaseEntry& e = c.entry;
    if (e.params.empty()) {
      EXPECT_FALSE(e.tuned()) << e.curve;
      EXPECT_EQ(e.curve, e.method + "/rk4");
    } else {
      EXPECT_TRUE(e.tuned()) << e.curve;
      EXPECT_EQ(e.curve, e.method + "/rk4 tuned");
      params_of[e.method].insert(e.params);
    }
  }
  std::set<std::string> want_lambda, want_alpha;
  for (double g : lambdas) want_lambda.insert("lambda=" + format_short(g));
  for (double g : alphas) want_alpha.insert("alpha=" + format_short(g) + ";beta=" + format_short(g));  // beta tied
  EXPECT_EQ(params_of["pesterev"], want_lambda);
  EXPECT_EQ(params_of["baumgarte"], want_alpha);
  EXPECT_EQ(params_of.count("minimal"), 0u);
}

TEST(MatrixExpand, ShardsPartitionTheCases) {
  const auto all = expand_matrix(parse_matrix(kSmall, "s.toml"), registry_catalog()).cases;
  for (int n : {1, 2, 3, 5}) {
    std::multiset<size_t> seen;
    for (int k = 1; k <= n; ++k) {
      const auto shard = select_cases(all, "", k, n);
      EXPECT_LE(shard.size(), all.size() / n + 1);
      for (size_t i = 1; i < shard.size(); ++i) EXPECT_LT(shard[i - 1].entry.index, shard[i].entry.index);
      for (const auto& c : shard) seen.insert(c.entry.index);
      // Same answer every time.
      const auto again = select_cases(all, "", k, n);
      ASSERT_EQ(again.size(), shard.size());
      for (size_t i = 0; i < shard.size(); ++i) EXPECT_EQ(again[i].entry.id, shard[i].entry.id);
    }
    ASSERT_EQ(seen.size(), all.size()) << n << " shards";
    for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(seen.count(i), 1u);
  }
  EXPECT_THROW(parse_shard("0/4"), UsageError);
  EXPECT_THROW(parse_shard("5/4"), UsageError);
  EXPECT_THROW(parse_shard("2"), UsageError);
  EXPECT_EQ(parse_shard("3/4"), std::make_pair(3, 4));
}

TEST(MatrixExpand, DefaultMatrixCoversEveryApplicableProblemMethodPair) {
  const auto ex = expand_matrix(parse_matrix(cli::default_matrix_text(), "<default>"), registry_catalog());
  std::set<std::pair<std::string, std::string>> covered;
  for (const auto& c : ex.cases) covered.insert({c.entry.problem, c.entry.method});
  for (const auto& p : all_problems())
    for (const auto& m : all_methods())
      if (p->why_not(m.name).empty()) {
        EXPECT_TRUE(covered.count({p->info().name, m.name})) << p->info().name << " x " << m.name;
      }
}

TEST(MatrixExpand, ShippedMatricesExpand) {
  size_t files = 0;
  for (const auto& f : fs::directory_iterator(CSTAB_SOURCE_DIR "/matrices")) {
    if (f.path().extension() != ".toml") continue;
    ++files;
    const auto ex = expand_matrix(read_matrix_file(f.path().string()), registry_catalog());
    EXPECT_FALSE(ex.cases.empty()) << f.path();
  }
  EXPECT_GE(files, 1u);
}

// ---------------------------------------------------------------------------
// Runs of the binary.

using cstab::testing::Outcome;
Outcome sh(const std::string& command) { return cstab::testing::run_shell(command); }

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A TOML syntax error: one line on stderr naming file:line:column, exit 2,
// nothing listed or written.
TEST(MatrixCli, SyntaxErrorExitsTwoWithFileLineColumnAndNoOutput) {
  char tmpl[] = "/tmp/cstab-test-matrix-syntax-XXXXXX";
  const std::string dir = ::mkdtemp(tmpl);
  std::ofstream(dir + "/bad.toml") << "[[sweep]]\nproblems = [\"wheel\"]\nstep = [1e-3, 2e-3\nt_end = 1\n";
  for (const char* what : {" --list", " --out "}) {
    SCOPED_TRACE(what);
    const std::string out_dir = dir + "/out";
    const Outcome o = sh(std::string(CSTAB_BINARY) + " matrix " + dir + "/bad.toml" + what +
                        (std::string(what) == " --out " ? out_dir : ""));
    EXPECT_EQ(o.code, 2) << o.out;
    const std::string prefix = "cstab matrix: error: " + dir + "/bad.toml:4:1: ";
    EXPECT_EQ(o.out.substr(0, prefix.size()), prefix) << o.out;
    EXPECT_NE(o.out.find("array"), std::string::npos) << o.out;
    EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 1) << o.out;
    EXPECT_FALSE(fs::exists(out_dir));
  }
  fs::remove_all(dir);
}

class MatrixRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char tmpl[] = "/tmp/cstab-test-matrix-XXXXXX";
    dir_ = ::mkdtemp(tmpl);
    std::ofstream(dir_ + "/tiny.toml") << R"(# the tests' matrix: a few fast wheel cases
[defaults]
problems = ["wheel"]
methods = "all"
t_end = 0.5
ref_time = 0.5
repeats = 2

[[sweep]]
name = "fixed"
integrators = "rk4"
step = [1e-3, 5e-4]
methods = ["pesterev", "minimal"]

[[sweep]]
name = "adaptive"
integrators = "rk8pd"
tol = [1e-6, 1e-9]
methods = ["pesterev", "minimal"]

[[sweep]]
name = "long"
integrators = "rk8pd"
tol = 1e-8
t_end = 1
repeats = 1
work_precision = false
overlay = true
methods = ["pesterev", "minimal"]
)";
    single_ = sh(std::string(CSTAB_BINARY) + " matrix " + dir_ + "/tiny.toml --out " + dir_ + "/single --jobs 2");
  }
  static void TearDownTestSuite() {
    if (!::testing::Test::HasFailure()) fs::remove_all(dir_);
  }
  static std::string dir_;
  static Outcome single_;
};
std::string MatrixRun::dir_;
Outcome MatrixRun::single_;

TEST_F(MatrixRun, SingleRunWritesResultsPlotsAndReport) {
  ASSERT_EQ(single_.code, 0) << single_.out;
  EXPECT_NE(single_.out.find("10 cases: 10 run, 0 cached, in "), std::string::npos) << single_.out;
  for (const char* f : {"summary.csv", "cases.csv", "matrix.toml", "provenance.txt", "work_precision.csv",
                        "fastest.csv", "report.html", "plots/wheel_work_precision.png", "plots/wheel_overlay.png",
                        "plots/wheel_trajectory.png", "plots/replot.sh", "plots/data/wheel_overlay.dat.gz"})
    EXPECT_TRUE(fs::exists(dir_ + "/single/" + f)) << f;
  // SVGs only on demand (ReportPicturesOnDemand); the plotted data gzip-compressed.
  for (const auto& e : fs::directory_iterator(dir_ + "/single/plots"))
    EXPECT_NE(e.path().extension(), ".svg") << e.path();
  for (const auto& e : fs::directory_iterator(dir_ + "/single/plots/data"))
    EXPECT_NE(e.path().extension(), ".dat") << e.path();
  const CsvTable s = read_csv(dir_ + "/single/summary.csv");
  EXPECT_EQ(s.header[0], "case_id");
  EXPECT_EQ(s.header[1], "repeat");
  EXPECT_EQ(s.header[2], "sweep");
  EXPECT_EQ(s.rows.size(), 8u * 2 + 2);  // repeats
  const std::string prov = slurp(dir_ + "/single/provenance.txt");
  for (const char* key : {"git_revision: ", "compiler: ", "cxx_flags: ", "eigen: 3.", "gsl: ", "sundials: ", "cpu: ",
                          "date: "})
    EXPECT_NE(prov.find(key), std::string::npos) << key;
  const std::string html = slurp(dir_ + "/single/report.html");
  // The pictures are linked from plots/, not inlined.
  EXPECT_NE(html.find("<img alt=\"wheel_overlay\" src=\"plots/wheel_overlay.png\">"), std::string::npos);
  EXPECT_EQ(html.find("data:image"), std::string::npos);
  EXPECT_NE(html.find("Fastest method at each accuracy level"), std::string::npos);
}

// The rankings (issue 22): stabilization methods ranked among themselves;
// the constraint-free baselines (minimal here) apart as limits, each row's
// time a multiple of the fastest method's and of the fastest limit's.
TEST_F(MatrixRun, FastestTablesRankStabilizationMethodsWithLimitsApart) {
  ASSERT_EQ(single_.code, 0) << single_.out;
  const CsvTable f = read_csv(dir_ + "/single/fastest.csv");
  ASSERT_FALSE(f.rows.empty());
  // (problem, measure, threshold) -> role -> walls in rank order.
  std::map<std::string, std::map<std::string, std::vector<double>>> groups;
  size_t limits = 0, methods = 0;
  for (size_t r = 0; r < f.rows.size(); ++r) {
    const std::string method = f.get(r, "method"), role = f.get(r, "role");
    EXPECT_EQ(role, method == "minimal" || method == "none" ? "limit" : "method") << method;
    (role == "limit" ? limits : methods) += 1;
    auto& walls = groups[f.get(r, "problem") + "," + f.get(r, "measure") + "," + f.get(r, "threshold")][role];
    walls.push_back(std::stod(f.get(r, "wall_median_s")));
    EXPECT_EQ(f.get(r, "rank"), std::to_string(walls.size()));
  }
  EXPECT_GT(limits, 0u);
  EXPECT_GT(methods, 0u);
  for (size_t r = 0; r < f.rows.size(); ++r) {
    const auto& g = groups[f.get(r, "problem") + "," + f.get(r, "measure") + "," + f.get(r, "threshold")];
    const double wall = std::stod(f.get(r, "wall_median_s"));
    auto ratio_to = [&](const char* role, const char* column) {
      const auto it = g.find(role);
      if (it == g.end()) {
        EXPECT_EQ(f.get(r, column), "") << column;
        return;
      }
      EXPECT_NEAR(std::stod(f.get(r, column)), wall / it->second.front(), 1e-9 * wall / it->second.front());
    };
    ratio_to("method", "ratio_to_fastest");
    ratio_to("limit", "ratio_to_limit");
  }
  for (const auto& [key, roles] : groups)
    for (const auto& [role, walls] : roles) EXPECT_TRUE(std::is_sorted(walls.begin(), walls.end())) << key << role;
  const std::string html = slurp(dir_ + "/single/report.html");
  EXPECT_NE(html.find("Stabilization methods against the limits"), std::string::npos);
  // The limit is minimal, on rk8pd or rk4: whichever of its curves reached
  // the level in less wall time (either, on a loaded machine).
  EXPECT_NE(html.find("<td><i>limit</i></td><td>minimal/"), std::string::npos);
  EXPECT_EQ(html.find("<td class=\"win\">minimal"), std::string::npos) << "a limit crowned fastest";
}

TEST_F(MatrixRun, UnchangedRerunRunsNothing) {
  ASSERT_EQ(single_.code, 0) << single_.out;
  const std::string before = slurp(dir_ + "/single/summary.csv");
  const Outcome again = sh(std::string(CSTAB_BINARY) + " matrix " + dir_ + "/tiny.toml --out " + dir_ + "/single");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("10 of 10 cases cached"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("0 run, 10 cached"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("0 plots drawn"), std::string::npos) << again.out;
  EXPECT_EQ(slurp(dir_ + "/single/summary.csv"), before);  // nothing rerun: even the timings are the same
  // No wall-time bound here (a timed test fails under the sanitizers and on a
  // loaded machine): "0 run", "0 plots drawn" and the unchanged summary say
  // that nothing was redone.
}

TEST_F(MatrixRun, TwoShardsThroughGnuParallelMergeToTheSingleRun) {
  ASSERT_EQ(single_.code, 0) << single_.out;
  ASSERT_EQ(sh("command -v parallel").code, 0) << "GNU parallel is not installed (scripts/install-deps.sh)";
  const Outcome shards = sh("cd " + dir_ + " && parallel --will-cite " + CSTAB_BINARY +
                           " matrix tiny.toml --shard {}/2 --out shard{} --jobs 1 ::: 1 2");
  ASSERT_EQ(shards.code, 0) << shards.out;
  const size_t n1 = read_csv(dir_ + "/shard1/cases.csv").rows.size();
  const size_t n2 = read_csv(dir_ + "/shard2/cases.csv").rows.size();
  EXPECT_EQ(n1 + n2, 10u);
  EXPECT_GE(n1, 4u);
  EXPECT_GE(n2, 4u);
  const Outcome merge = sh(std::string(CSTAB_BINARY) + " merge " + dir_ + "/merged " + dir_ + "/shard1 " + dir_ +
                          "/shard2 --no-report");
  ASSERT_EQ(merge.code, 0) << merge.out;
  EXPECT_EQ(cstab::testing::summary_without_timing(dir_ + "/merged/summary.csv"),
            cstab::testing::summary_without_timing(dir_ + "/single/summary.csv"));
  EXPECT_EQ(slurp(dir_ + "/merged/cases.csv"), slurp(dir_ + "/single/cases.csv"));
  // A missing shard is reported, with exit code 3.
  const Outcome partial = sh(std::string(CSTAB_BINARY) + " merge " + dir_ + "/partial " + dir_ + "/shard1 --no-report");
  EXPECT_EQ(partial.code, 3) << partial.out;
}

// The pictures' names in a folder's plots/ with the given extension.
std::set<std::string> pictures(const std::string& plots, const std::string& ext) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(plots))
    if (e.path().extension() == ext) names.insert(e.path().stem().string());
  return names;
}

// SVGs on demand: `cstab report --svg` draws one per PNG, a plain report
// keeps them while nothing changed; plots/replot.sh redraws both formats,
// and the PNGs it draws are the ones cstab drew.
// (The sweep "fixed" alone: the tiny matrix's "long" sweep is too short for
// its drift picture, whose gnuplot fails.)
TEST_F(MatrixRun, ReportPicturesOnDemand) {
  const std::string dir = dir_ + "/svg", plots = dir + "/plots";
  Outcome o = sh(std::string(CSTAB_BINARY) + " matrix " + dir_ + "/tiny.toml --filter fixed --out " + dir);
  ASSERT_EQ(o.code, 0) << o.out;
  const std::set<std::string> png = pictures(plots, ".png");
  EXPECT_EQ(png, (std::set<std::string>{"wheel_overlay", "wheel_trajectory", "wheel_work_precision"}));
  EXPECT_TRUE(pictures(plots, ".svg").empty());
  o = sh(std::string(CSTAB_BINARY) + " report " + dir + " --svg");
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("(" + std::to_string(png.size()) + " plots drawn, 0 unchanged)"), std::string::npos) << o.out;
  EXPECT_EQ(pictures(plots, ".svg"), png);
  EXPECT_NE(slurp(dir + "/report.html").find("<code>plots/wheel_overlay.svg</code>"), std::string::npos);
  o = sh(std::string(CSTAB_BINARY) + " report " + dir);
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("(0 plots drawn, " + std::to_string(png.size()) + " unchanged)"), std::string::npos) << o.out;
  EXPECT_EQ(pictures(plots, ".svg"), png);
  // replot.sh: the same PNGs, and the SVGs again after they were removed.
  const std::string first = slurp(plots + "/wheel_overlay.png");
  for (const auto& name : png) fs::remove(plots + "/" + name + ".svg");
  o = sh("sh " + plots + "/replot.sh");
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_EQ(pictures(plots, ".svg"), png);
  EXPECT_EQ(slurp(plots + "/wheel_overlay.png"), first);
  // Without --svg, a redrawn picture loses its SVG (it would be stale).
  fs::remove(plots + "/data/wheel_overlay.stamp");
  o = sh(std::string(CSTAB_BINARY) + " report " + dir);
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_FALSE(fs::exists(plots + "/wheel_overlay.svg"));
  EXPECT_TRUE(fs::exists(plots + "/wheel_trajectory.svg"));
  // --svg where nothing is drawn is bad input, and changes nothing.
  for (const std::string& bad : {" report " + dir + " --svg --no-plots", " merge " + dir_ + "/svg2 " + dir +
                                                                          " --svg --no-report"}) {
    o = sh(std::string(CSTAB_BINARY) + bad);
    EXPECT_EQ(o.code, 2) << bad << "\n" << o.out;
    EXPECT_NE(o.out.find("--svg: draws the pictures; not with --no-"), std::string::npos) << o.out;
  }
  EXPECT_FALSE(fs::exists(dir_ + "/svg2"));
  o = sh(std::string(CSTAB_BINARY) + " matrix " + dir_ + "/tiny.toml --out " + dir_ + "/svg3 --shard 1/2 --svg");
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_FALSE(fs::exists(dir_ + "/svg3"));
}

TEST_F(MatrixRun, ReportOpensInHeadlessChromiumWithEveryImageLoaded) {
  ASSERT_EQ(single_.code, 0) << single_.out;
  const Outcome check = sh("bash " CSTAB_SOURCE_DIR "/scripts/check-report.sh " + dir_ + "/single " + dir_ + "/shot.png");
  if (check.code == 77) GTEST_SKIP() << check.out;
  ASSERT_EQ(check.code, 0) << check.out;
  EXPECT_NE(check.out.find("images loaded"), std::string::npos) << check.out;
  EXPECT_TRUE(fs::exists(dir_ + "/shot.png"));
}

// Key `tune`: the work-precision picture draws a tuned curve as its
// envelope (every case of the curve that no other beats in both wall time
// and error against the reference), and the report compares each tuned
// curve with its default-gain curve.
TEST(MatrixTune, ReportDrawsTheEnvelopeAndComparesItWithTheDefaults) {
  char tmpl[] = "/tmp/cstab-test-matrix-tune-XXXXXX";
  const std::string dir = ::mkdtemp(tmpl);
  std::ofstream(dir + "/t.toml") << "[[sweep]]\nproblems = [\"wheel\"]\nmethods = [\"pesterev\", \"minimal\"]\n"
                                    "integrators = \"rk4\"\nstep = [1e-2, 3e-3, 1e-3]\nt_end = 1\nref_time = 1\n"
                                    "tune = 5\nseries = false\n";
  const Outcome o = sh(std::string(CSTAB_BINARY) + " matrix " + dir + "/t.toml --out " + dir + "/out --jobs 2");
  ASSERT_EQ(o.code, 0) << o.out;
  // The tuned curve's cases, from work_precision.csv: (wall, error).
  const CsvTable wp = read_csv(dir + "/out/work_precision.csv");
  std::vector<std::pair<double, double>> tuned;
  for (size_t r = 0; r < wp.rows.size(); ++r)
    if (wp.get(r, "curve") == "pesterev/rk4 tuned" && wp.get(r, "status") == "ok" && !wp.get(r, "ref_error").empty())
      tuned.emplace_back(std::stod(wp.get(r, "wall_median_s")), std::stod(wp.get(r, "ref_error")));
  ASSERT_EQ(tuned.size() > 5, true) << "5 gains x 3 steps, some diverge";
  std::set<double> non_dominated;
  for (const auto& p : tuned)
    if (std::none_of(tuned.begin(), tuned.end(), [&](const std::pair<double, double>& d) {
          return (d.first < p.first && d.second <= p.second) || (d.first <= p.first && d.second < p.second);
        }))
      non_dominated.insert(p.first);
  // The picture's block of that curve.
  const Outcome dat = sh("zcat " + dir + "/out/plots/data/wheel_work_precision.dat.gz");
  ASSERT_EQ(dat.code, 0) << dat.out;
  const size_t at = dat.out.find("\"pesterev/rk4 tuned\"");
  ASSERT_NE(at, std::string::npos) << dat.out;
  std::istringstream block(dat.out.substr(at, dat.out.find("\n\n", at) - at));
  std::string line;
  std::getline(block, line);  // header
  std::set<double> drawn;
  double last_wall = 0, last_error = INFINITY;
  while (std::getline(block, line)) {
    std::istringstream cells(line);
    double wall = 0, error = 0;
    cells >> wall >> error;
    EXPECT_GE(wall, last_wall);
    EXPECT_LT(error, last_error);
    last_wall = wall;
    last_error = error;
    drawn.insert(wall);
  }
  // The same walls (the data file keeps 7 digits).
  ASSERT_EQ(drawn.size(), non_dominated.size());
  for (auto a = drawn.begin(), b = non_dominated.begin(); a != drawn.end(); ++a, ++b)
    EXPECT_NEAR(*a, *b, 1e-6 * *b);
  // The comparison table: the speed-up is the default-gain curve's fastest
  // case reaching 1e-6 over the tuned curve's, or the default is flagged.
  const std::string html = slurp(dir + "/out/report.html");
  EXPECT_NE(html.find("Tuned gains against the defaults"), std::string::npos);
  const size_t row = html.find("<tr><td class=\"num\">1e-06</td><td>pesterev/rk4 tuned</td>");
  ASSERT_NE(row, std::string::npos);
  auto fastest = [&](const std::string& curve) {
    double best = INFINITY;
    for (size_t r = 0; r < wp.rows.size(); ++r)
      if (wp.get(r, "curve") == curve && wp.get(r, "status") == "ok" && !wp.get(r, "ref_error").empty() &&
          std::stod(wp.get(r, "ref_error")) <= 1e-6)
        best = std::min(best, std::stod(wp.get(r, "wall_median_s")));
    return best;
  };
  const double t = fastest("pesterev/rk4 tuned"), d = fastest("pesterev/rk4");
  ASSERT_TRUE(std::isfinite(t));
  const std::string tr = html.substr(row, html.find("</tr>", row) - row);
  if (!std::isfinite(d) || d > 3 * t)
    EXPECT_NE(tr.find("<b>flagged</b>"), std::string::npos) << tr;
  else
    EXPECT_NE(tr.find(format_3g(d / t) + "&times;"), std::string::npos) << tr;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cstab

// cstab-peer-sundials (peers/sundials/): SUNDIALS' own slider-crank example
// with cstab's options and trajectory file added at build time. As shipped it
// still prints the shipped output; its trajectory starts at cstab's own
// initial state, scores through `cstab score`, and its error and residual
// fall with its tolerance; bad options and a failing solve end as documented
// (exit 2 or 1, no file). The program's path comes from
// peers/sundials/CMakeLists.txt; without the example installed the program
// is not built and these tests skip.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "matrix/matrix.hpp"
#include "tests/support/test_util.hpp"

namespace {

namespace fs = std::filesystem;
using cstab::testing::contains;
using cstab::testing::Outcome;
using cstab::testing::quote;
using cstab::testing::run_shell;

#ifdef CSTAB_PEER_SUNDIALS
const char* kPeer = CSTAB_PEER_SUNDIALS;
#define SKIP_WITHOUT_PEER() (void)0
#else
const char* kPeer = "";
#define SKIP_WITHOUT_PEER() GTEST_SKIP() << "cstab-peer-sundials is not built (SUNDIALS' examples not installed)"
#endif

// The example's table rows ("t y1 y2 y3 | nst k h") and its step count line.
std::vector<std::string> table_rows(const std::string& text) {
  std::vector<std::string> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if ((line.size() > 6 && line.find('|') != std::string::npos && (std::isdigit(line[1]) || line[0] == '1')) ||
        line.rfind("Number of steps", 0) == 0)
      rows.push_back(line);
  return rows;
}

class PeerSundials : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() / ("cstab-test-sundials-" + std::to_string(::getpid()) + "-" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  Outcome peer(const std::string& args) { return run_shell(quote(kPeer) + " " + args); }

  // The peer's trajectory at tolerance `tol`, scored: the summary table.
  cstab::CsvTable scored(const std::string& tol) {
    const fs::path csv = dir / ("sc-" + tol + ".csv"), out = dir / ("scored-" + tol);
    const Outcome p = peer("--problem slider-crank --tol " + tol + " --t-end 10 --every 0.1 --out " + quote(csv));
    EXPECT_EQ(p.code, 0) << p.out;
    const Outcome s = cstab::testing::cstab_cmd("score --problem slider-crank " + quote(csv) + " --out " + quote(out));
    EXPECT_EQ(s.code, 0) << s.out;
    return cstab::read_csv((out / "summary.csv").string());
  }
};

TEST_F(PeerSundials, WithoutOptionsItPrintsTheShippedOutput) {
  SKIP_WITHOUT_PEER();
  const Outcome o = peer("");
  ASSERT_EQ(o.code, 0) << o.out;
  // The shipped output, copied beside the program by peers/sundials/patch.cmake.
  const std::string shipped = cstab::testing::slurp(fs::path(kPeer).parent_path() / "idasSlCrank_dns.out");
  const auto want = table_rows(shipped), got = table_rows(o.out);
  ASSERT_EQ(want.size(), 27u) << shipped;  // t = 0, 0.4, ..., 10 and the step count
  EXPECT_EQ(got, want);
}

TEST_F(PeerSundials, ItsTrajectoryStartsAtCstabsStateAndConvergesWithItsTolerance) {
  SKIP_WITHOUT_PEER();
  const cstab::CsvTable loose = scored("1e-4"), tight = scored("1e-7");
  ASSERT_EQ(loose.rows.size(), 1u);
  ASSERT_EQ(tight.rows.size(), 1u);
  const auto num = [](const cstab::CsvTable& t, const char* k) { return std::stod(t.get(0, k)); };
  for (const auto* t : {&loose, &tight}) {
    EXPECT_EQ(t->get(0, "status"), "ok");
    EXPECT_EQ(num(*t, "steps"), 100);  // rows every 0.1 s to t = 10, t = 10 itself a row
    EXPECT_EQ(t->get(0, "ref_interpolation"), "row");
    EXPECT_EQ(t->get(0, "differenced"), "none");  // the example's velocities are written
    EXPECT_LE(num(*t, "initial_state_deviation"), 1e-15);
    EXPECT_GT(num(*t, "wall_seconds"), 0);  // the solve's own timer, from the file
  }
  // Three decades of tolerance: at least two of error at t = 10 and of residual.
  EXPECT_LT(num(tight, "ref_error"), num(loose, "ref_error") / 100);
  EXPECT_LT(num(tight, "max_residual"), num(loose, "max_residual") / 100);
  // The error is of the order of the tolerance (the example's own rtol, atol = rtol / 10).
  EXPECT_LT(num(tight, "ref_error"), 1e-4 * 1e-2);
}

TEST_F(PeerSundials, BadOptionsExitTwoNamingTheOptionAndWriteNothing) {
  SKIP_WITHOUT_PEER();
  const fs::path out = dir / "t.csv";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--tol nan", "--tol must be a number > 0: nan"},
      {"--tol -1e-6", "--tol must be a number > 0: -1e-6"},
      {"--t-end 1e400", "--t-end must be a number > 0: 1e400"},
      {"--problem pendulum", "only the problem slider-crank, not: pendulum"},
      {"--t-end 1 --every 0.3", "--t-end must be a whole multiple"},
      {"--step 1e-3", "unknown option"},
      {"--tol", "option without a value: --tol"},
  };
  for (const auto& [args, message] : cases) {
    const Outcome o = peer("--out " + quote(out) + " " + args);
    EXPECT_EQ(o.code, 2) << args << "\n" << o.out;
    EXPECT_TRUE(contains(o.out, message)) << args << "\n" << o.out;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

// Below rtol 3e-8 the example's Newton iteration fails at its first steps
// (docs/peers.md): exit 1 with IDAS's message, and no trajectory, not a
// partial one. In a matrix that is a `failed` external case.
TEST_F(PeerSundials, AFailingSolveExitsOneAndLeavesNoFile) {
  SKIP_WITHOUT_PEER();
  const fs::path out = dir / "t.csv";
  const Outcome o = peer("--tol 1e-9 --out " + quote(out));
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_TRUE(contains(o.out, "IDASolve")) << o.out;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir / "t.csv.tmp"));
}

}  // namespace

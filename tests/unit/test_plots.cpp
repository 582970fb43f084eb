// plots/wheel.gp on a real (short) run's series.csv: every PNG is written,
// is a PNG, and gnuplot reports no error.
#include <gtest/gtest.h>

#include "tests/support/test_util.hpp"
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using cstab::testing::exit_code;
using cstab::testing::quote;
using cstab::testing::slurp;

// A scratch folder per test, removed afterwards.
struct Scratch : cstab::testing::Scratch {
  Scratch() : cstab::testing::Scratch("cstab_plots") {}
};

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

const fs::path kScript = fs::path(CSTAB_SOURCE_DIR) / "plots" / "wheel.gp";

TEST(WheelPlots, ScriptWritesReadablePngs) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot not installed";
  ASSERT_TRUE(fs::exists(kScript)) << kScript;
  Scratch s;
  const fs::path run = s.dir() / "run with space";  // paths are quoted properly
  const std::string cmd = quote(CSTAB_BINARY) +
                          " run --problem wheel --method pesterev --integrator rk4 --step 1e-3 --t-end 1"
                          " --out " + quote(run.string()) + " >/dev/null 2>&1";
  ASSERT_EQ(exit_code(std::system(cmd.c_str())), 0) << cmd;
  ASSERT_TRUE(fs::exists(run / "series.csv"));

  const fs::path err = s.dir() / "gnuplot.err";
  const std::string gp = "gnuplot -e " +
                         quote("series='" + (run / "series.csv").string() + "'; outdir='" + run.string() + "'") +
                         " " + quote(kScript.string()) + " 2>" + quote(err.string());
  EXPECT_EQ(exit_code(std::system(gp.c_str())), 0) << gp << "\n" << slurp(err);
  std::string messages = slurp(err);
  std::transform(messages.begin(), messages.end(), messages.begin(), [](unsigned char c) { return std::tolower(c); });
  EXPECT_EQ(messages.find("error"), std::string::npos) << messages;

  for (const char* name : {"wheel_residuals.png", "wheel_xz.png", "wheel_phi.png", "wheel_pendulum.png"}) {
    const fs::path png = run / name;
    ASSERT_TRUE(fs::exists(png)) << png;
    EXPECT_GT(fs::file_size(png), 2000u) << png << " is (nearly) empty";
    const std::string head = slurp(png).substr(0, 8);
    EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8)) << png << " is not a PNG";
  }
}

TEST(WheelPlots, ScriptWithoutArgumentsExplainsUsage) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot not installed";
  Scratch s;
  const fs::path out = s.dir() / "out.txt";
  const std::string gp = "cd " + quote(s.dir().string()) + " && gnuplot " + quote(kScript.string()) + " >" +
                         quote(out.string()) + " 2>&1";
  EXPECT_NE(exit_code(std::system(gp.c_str())), 0);
  EXPECT_NE(slurp(out).find("usage"), std::string::npos) << slurp(out);
  // Nothing written into the working folder.
  for (const auto& e : fs::directory_iterator(s.dir()))
    EXPECT_EQ(e.path().extension(), ".txt") << e.path();
}

}  // namespace

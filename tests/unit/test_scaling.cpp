// The report's Scaling section (report/scaling.hpp): the exponent fit
// against closed forms, and a matrix run over three sizes of n-four-bar
// whose section is checked against the cases it was built from (the cost
// per step recomputed from summary.csv; the fastest case within the level
// found again). No timing is asserted: wall times are the measurement, not
// the test.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "report/scaling.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

TEST(ScalingFit, SlopeOfAPowerLawIsItsExponent) {
  std::vector<std::pair<double, double>> pts;
  for (double n : {5.0, 10.0, 20.0, 40.0, 80.0}) pts.push_back({n, 3e-6 * std::pow(n, 1.5)});
  EXPECT_NEAR(fit_log_log_slope(pts), 1.5, 1e-12);
  // Least squares off a power law: ln x = 0, l, 2l (l = ln 2), ln y = 0, 3l, 4l;
  // slope = sum (x - l)(y - ybar) / sum (x - l)^2 = (l ybar + l (4l - ybar)) / (2 l^2) = 2.
  EXPECT_NEAR(fit_log_log_slope({{1, 1}, {2, 8}, {4, 16}}), 2.0, 1e-12);
  // Points that cannot be on a log-log plot are left out; too few give NaN.
  EXPECT_NEAR(fit_log_log_slope({{1, 1}, {2, 2}, {3, 0}, {-1, 5}, {4, 4}}), 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(fit_log_log_slope({{2, 3}})));
  EXPECT_TRUE(std::isnan(fit_log_log_slope({{2, 3}, {2, 5}})));
}

TEST(ScalingSection, MatrixRunRendersItFromItsCases) {
  testing::Scratch s;
  const std::string dir = s.dir().string();
  {
    std::ofstream f(dir + "/scaling.toml");
    f << "[defaults]\nproblems = [\"n-four-bar\"]\nmethods = [\"projection\"]\nintegrators = [\"rk4\"]\n"
         "t_end = 2\nref_time = 2\nseries = false\n"
         "[[sweep]]\nname = \"band\"\nproblem_param.N = [3, 6, 12]\nstep = [1e-2, 5e-3]\n"
         "[[sweep]]\nname = \"dense\"\nproblem_param.N = [3, 6, 12]\nparam.kkt = 1\nstep = [1e-2, 5e-3]\n"
         "[[sweep]]\nname = \"two-sizes\"\nmethods = [\"post-stabilization\"]\nproblem_param.N = [3, 6]\n"
         "step = 1e-2\n";
  }
  const std::string cmd = std::string(CSTAB_BINARY) + " matrix " + dir + "/scaling.toml --out " + dir +
                          "/out --jobs 2 > " + dir + "/log.txt 2>&1";
  ASSERT_EQ(testing::exit_code(std::system(cmd.c_str())), 0) << testing::slurp(dir + "/log.txt");
  const CsvTable scaling = read_csv(dir + "/out/scaling.csv");
  // Two curves of three sizes; post-stabilization has two sizes only: not a curve.
  ASSERT_EQ(scaling.rows.size(), 6u);
  const CsvTable summary = read_csv(dir + "/out/summary.csv");
  for (size_t r = 0; r < scaling.rows.size(); ++r) {
    EXPECT_EQ(scaling.get(r, "problem"), "n-four-bar");
    EXPECT_EQ(scaling.get(r, "parameter"), "N");
    const std::string curve = scaling.get(r, "curve");
    const bool dense = curve.find("kkt=1") != std::string::npos;
    EXPECT_EQ(curve, dense ? "projection[natural]/rk4 kkt=1" : "projection[natural]/rk4");
    const std::string n = scaling.get(r, "size");
    EXPECT_EQ(scaling.get(r, "cases"), "2");
    // Recomputed from summary.csv: the median (of two: the mean) of wall / steps.
    // One repeat per case (the matrix default): its wall time is the case's median.
    std::vector<double> per_step;
    double fastest = 1e300, fastest_step = 0;
    const double level = std::stod(scaling.get(r, "level"));
    for (size_t k = 0; k < summary.rows.size(); ++k) {
      if (summary.get(k, "problem_params") != "N=" + n || summary.get(k, "method") != "projection") continue;
      if ((summary.get(k, "params").find("kkt=1") != std::string::npos) != dense) continue;
      ASSERT_EQ(summary.get(k, "status"), "ok");
      const double wall = std::stod(summary.get(k, "wall_seconds"));
      per_step.push_back(wall / std::stod(summary.get(k, "steps")));
      if (std::stod(summary.get(k, "ref_error")) <= level && wall < fastest) {
        fastest = wall;
        fastest_step = std::stod(summary.get(k, "step"));
      }
    }
    ASSERT_EQ(per_step.size(), 2u) << n;
    EXPECT_NEAR(std::stod(scaling.get(r, "cost_per_step_s")), (per_step[0] + per_step[1]) / 2, 1e-9 * per_step[0]) << n;
    const std::string setting = scaling.get(r, "setting_at_level");
    ASSERT_EQ(setting.rfind("step=", 0), 0u) << setting;
    EXPECT_EQ(std::stod(setting.substr(5)), fastest_step) << n;
    EXPECT_TRUE(std::isfinite(std::stod(scaling.get(r, "step_exponent"))));
  }
  const std::string html = testing::slurp(dir + "/out/report.html");
  EXPECT_NE(html.find("<h2 id=\"scaling\">Scaling</h2>"), std::string::npos);
  EXPECT_NE(html.find("id=\"scaling-n-four-bar\""), std::string::npos);
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/plots/n-four-bar_scaling.png"));
  }
}

}  // namespace
}  // namespace cstab

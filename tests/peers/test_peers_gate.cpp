// The short peers matrix CI runs (issue 20): every other engine at its
// default settings as external cases of matrices/peers-defaults.toml, with
// the paths of the peers this build made, then the committed gate on them
// (matrices/peers-defaults-thresholds.csv), which holds each engine's
// residual class at its defaults. The peers' paths come from their
// CMakeLists (peers/*/); where one is not built the test skips.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "matrix/matrix.hpp"
#include "tests/support/test_util.hpp"

namespace {

namespace fs = std::filesystem;
using cstab::testing::contains;
using cstab::testing::cstab_cmd;
using cstab::testing::Outcome;
using cstab::testing::quote;

#if defined(CSTAB_PEER_SIMBODY) && defined(CSTAB_PEER_MUJOCO) && defined(CSTAB_PEER_SUNDIALS)
#define SKIP_WITHOUT_PEERS() (void)0
const char* kPeers[][2] = {{"build/release/peers/simbody/cstab-peer-simbody", CSTAB_PEER_SIMBODY},
                           {"build/release/peers/mujoco/cstab-peer-mujoco", CSTAB_PEER_MUJOCO},
                           {"build/release/peers/sundials/cstab-peer-sundials", CSTAB_PEER_SUNDIALS}};
#else
#define SKIP_WITHOUT_PEERS() GTEST_SKIP() << "not every peer is built (Simbody, MuJoCo, SUNDIALS' example)"
const char* kPeers[][2] = {{"", ""}};
#endif

TEST(PeersGate, EveryEngineAtItsDefaultsRunsAsACaseAndPassesTheCommittedGate) {
  SKIP_WITHOUT_PEERS();
  const fs::path dir = fs::temp_directory_path() / ("cstab-test-peers-gate-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string text = cstab::testing::slurp(fs::path(CSTAB_SOURCE_DIR) / "matrices" / "peers-defaults.toml");
  for (const auto& [relative, built] : kPeers) {
    size_t at = 0, n = 0;
    for (; (at = text.find(relative, at)) != std::string::npos; at += std::string(built).size(), ++n)
      text.replace(at, std::string(relative).size(), built);
    EXPECT_GT(n, 0u) << relative << " is not in matrices/peers-defaults.toml";
  }
  std::ofstream(dir / "m.toml") << text;
  const Outcome m = cstab_cmd("matrix " + quote(dir / "m.toml") + " --out " + quote(dir / "out") + " --jobs 2");
  ASSERT_EQ(m.code, 0) << m.out;
  // 4 Simbody integrators and MuJoCo's Euler on pendulum and slider crank,
  // SUNDIALS' example on the slider crank, 3 Simbody integrators on bricard
  // and on andrews, 4 on the car axis; on n-four-bar (N = 10) 3 Simbody
  // integrators and MuJoCo's Euler.
  EXPECT_TRUE(contains(m.out, "25 cases: 25 run, 0 cached")) << m.out;
  EXPECT_TRUE(contains(m.out, "25 ok")) << m.out;
  const cstab::CsvTable s = cstab::read_csv((dir / "out" / "summary.csv").string());
  ASSERT_EQ(s.rows.size(), 25u);
  for (size_t i = 0; i < s.rows.size(); ++i) {
    EXPECT_EQ(s.get(i, "integrator"), "external") << i;
    EXPECT_EQ(s.get(i, "status"), "ok") << s.get(i, "method");
  }
  // The report draws them as other engines, with the per-engine table.
  const std::string html = cstab::testing::slurp(dir / "out" / "report.html");
  for (const char* engine : {"simbody-rkmerson", "mujoco-euler", "sundials-idas"})
    EXPECT_TRUE(contains(html, engine)) << engine;
  const Outcome g = cstab_cmd("gate --strict --thresholds " +
                              quote(fs::path(CSTAB_SOURCE_DIR) / "matrices" / "peers-defaults-thresholds.csv") + " " +
                              quote(dir / "out"));
  EXPECT_EQ(g.code, 0) << g.out;
  EXPECT_TRUE(contains(g.out, ", 0 failed")) << g.out;
  EXPECT_TRUE(contains(g.out, "peers-defaults-thresholds.csv, results")) << g.out;
  fs::remove_all(dir);
}

}  // namespace

// The flyball governor (IFToMM A05, problems/flyball_governor): two
// independent formulations (natural coordinates with five rows and a constant
// mass matrix; Lagrange's equations in the shaft angle, slider height and rod
// angles) checked against each other and against the first integral they
// share, and the stiffness that makes it the benchmark's stiff problem: an
// explicit fixed-step method diverges at a step an implicit one runs.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "problems/flyball_governor/flyball_governor.hpp"
#include "problems/registry.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

constexpr int kCanonical = 18;

// A run to t_end with the reference at t_end: fixed-step and self-stepping
// schemes at h = 1e-3, adaptive ones at rtol = atol = 1e-10.
RunConfig config(const std::string& method, const std::string& integrator, double t_end) {
  StepSettings step;
  if (integrator == "rk4" || integrator == "own") step.step = 1e-3;
  else step.rtol = step.atol = 1e-10;
  RunConfig cfg = testing::quiet_run_config("flyball-governor", method, integrator, step, t_end);
  cfg.ref_time = t_end;
  return cfg;
}

// Both formulations start from the same state, on the rows at position and
// velocity level, with the springs at their rest length (the equilateral
// triangle hinge - rod midpoint - slider face of side 0.5).
TEST(FlyballModel, FormulationsShareTheStartWhichIsConsistent) {
  const FlyballGovernor problem;
  Vec<double, 9> q, v;
  problem.mechanical().initial_state(q, v);
  Vec<double, 8> y0;
  problem.minimal().initial_state(y0);
  double c[kCanonical];
  problem.minimal().to_canonical(0, y0, c);
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(c[i], q(i), 1e-15) << "coordinate " << i;
    EXPECT_NEAR(c[9 + i], v(i), 1e-14) << "velocity " << i;
  }
  double r[5];
  problem.minimal().residuals(0, y0, r);
  for (double x : r) EXPECT_NEAR(x, 0, 1e-15);
  // Spring 1: rod midpoint (H1 + P1) / 2 to slider face (d, 0, s).
  const FlyballParameters& p = problem.parameters();
  const double mx = (p.d + q(3)) / 2, mz = (1 + q(5)) / 2;
  EXPECT_NEAR(std::hypot(mx - p.d, mz - q(2)), p.l0, 1e-15);
  EXPECT_NEAR(std::hypot(mx - p.d, mz - 1), 0.5, 1e-15);
}

// The natural-coordinate mass matrix against the rigid-body kinetic energy:
// along any motion the minimal model allows, (M v) . (v turned about z)
// is J(alpha) theta', and 1/2 v^T M v is the minimal model's energy
// J theta'^2 / 2 + m_s s'^2 / 2 + A sum alpha_i'^2 / 2 (written out here).
TEST(FlyballModel, MassMatrixMatchesTheRigidBodyKineticEnergy) {
  const FlyballGovernor problem;
  const FlyballParameters& p = problem.parameters();
  const double a = p.L / 2, It = p.I_rod();
  for (const auto& y : {Vec<double, 8>((Vec<double, 8>() << 0.3, 0.45, 0.2, 0.7, 1.5, -0.3, 0.8, -1.1).finished()),
                        Vec<double, 8>((Vec<double, 8>() << -2.0, 0.6, -0.4, 1.2, -3.0, 0.2, -0.5, 2.0).finished())}) {
    double c[kCanonical];
    problem.minimal().to_canonical(0, y, c);
    const Vec<double, 9> q = vmap<9>(c), v = vmap<9>(c + 9);
    double J = p.I_axis(), T = 0.5 * p.m_slider * y(5) * y(5);
    for (int i = 0; i < 2; ++i) {
      const double co = std::cos(y(2 + i));
      J += p.m_rod * std::pow(p.d + a * co, 2) + It * co * co + p.m_point * std::pow(p.d + p.L * co, 2);
      T += 0.5 * (p.m_rod * a * a + It + p.m_point * p.L * p.L) * y(6 + i) * y(6 + i);
    }
    T += 0.5 * J * y(4) * y(4);
    EXPECT_NEAR(0.5 * v.dot(problem.mechanical().mass_matrix() * v), T, 1e-12 * T);
    EXPECT_NEAR(problem.mechanical().angular_momentum(q, v), J * y(4), 1e-12 * std::abs(J * y(4)));
    EXPECT_NEAR(problem.minimal().angular_momentum(y), J * y(4), 1e-12 * std::abs(J * y(4)));
    double r[5];
    problem.minimal().residuals(0, y, r);
    for (double x : r) EXPECT_NEAR(x, 0, 1e-14);
  }
}

// The reference keeps Lz and every row; the rods swing out (centrifugal
// force beats gravity at 2 pi rad/s), and with Lz conserved the shaft slows.
TEST(FlyballReference, KeepsAngularMomentumAndTheRows) {
  const FlyballGovernor problem;
  double c0[kCanonical], c[kCanonical], lz0, lz;
  ASSERT_TRUE(problem.reference(0, c0));
  problem.first_integrals(0, c0, &lz0);
  for (double t : {0.01, 0.5, 2.0, 10.0}) {
    ASSERT_TRUE(problem.reference(t, c)) << t;
    problem.first_integrals(t, c, &lz);
    EXPECT_NEAR(lz, lz0, 1e-11 * lz0) << "t = " << t;
    Vec<double, 5> phi;
    problem.mechanical().holonomic(0.0, vmap<9>(c).eval(), phi);
    EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-12) << "t = " << t;
  }
  // About the hinge, the point mass's centrifugal moment (m omega0^2 r L sin
  // 30 deg = 90 N m) beats gravity's (m g L cos 30 deg = 42 N m): the free
  // ends move out, J grows, and the shaft slows.
  EXPECT_GT(std::hypot(c[3], c[4]), c0[3]);
  const double omega = std::hypot(c[9], c[10]);
  EXPECT_LT(omega, problem.parameters().omega0);
}

// The DAE in natural coordinates agrees with the minimal-coordinate
// reference at t = 10 (independent formulations), with an explicit adaptive
// method whose step the stiffness bounds (projection on rk8pd, rtol = 1e-10:
// 2.9e-11 when this was written) and implicitly (cvode-bdf on Baumgarte's
// index-1 ODE, rtol = 1e-12: 5.2e-9), and both keep Lz.
TEST(FlyballReference, AgreesWithTheDaeInNaturalCoordinates) {
  const Problem& problem = find_problem("flyball-governor");
  struct Case {
    const char* method;
    const char* integrator;
    double tol, bound;
  };
  for (const Case& c : {Case{"projection", "rk8pd", 1e-10, 1e-9}, Case{"baumgarte", "cvode-bdf", 1e-12, 1e-7}}) {
    RunConfig cfg = config(c.method, c.integrator, 10);
    cfg.step.rtol = cfg.step.atol = c.tol;
    const RunResult r = run_case(problem, cfg, "");
    ASSERT_EQ(r.status, "ok") << c.method << "/" << c.integrator << ": " << r.reason;
    EXPECT_LT(r.ref_error, c.bound) << c.method << "/" << c.integrator;
    EXPECT_LT(r.max_residual, 1e-9) << c.method << "/" << c.integrator;
    ASSERT_EQ(r.max_integral_drift.size(), 1u);
    EXPECT_LT(r.max_integral_drift[0].second, c.bound) << c.method << "/" << c.integrator;
  }
}

// The stiffness, as an ordering: at h = 1e-3 (h times the fast rate 8e3 is
// 8, past RK4's real stability limit 2.785) RK4 diverges; the implicit
// generalized-alpha runs the same step to the end, near the reference.
TEST(FlyballStiffness, ExplicitFixedStepDivergesWhereImplicitRuns) {
  const Problem& problem = find_problem("flyball-governor");
  const RunResult explicit_run = run_case(problem, config("baumgarte", "rk4", 2), "");
  EXPECT_EQ(explicit_run.status, "diverged") << explicit_run.reason;
  const RunResult implicit_run = run_case(problem, config("generalized-alpha", "own", 2), "");
  ASSERT_EQ(implicit_run.status, "ok") << implicit_run.reason;
  EXPECT_LT(implicit_run.ref_error, 1e-2);
}

// RATTLE through the stiff dampers: its velocity half-kick is implicit in the
// damper forces, and fixed-point passes diverge once (h/2) times the fast
// rate passes 1 (h = 2.5e-4 here); Newton with dQ/dv takes over at every
// step, and the scheme keeps its second order and conserves Lz (the dampers
// are internal forces, equivariant under rotations about z).
TEST(FlyballStiffness, RattleRunsTheStiffDampersByNewtonAtSecondOrder) {
  const Problem& problem = find_problem("flyball-governor");
  double error[2];
  for (int k = 0; k < 2; ++k) {
    RunConfig cfg = config("rattle", "own", 2);
    cfg.step.step = k == 0 ? 2e-3 : 1e-3;
    const RunResult r = run_case(problem, cfg, "");
    ASSERT_EQ(r.status, "ok") << r.reason;
    error[k] = r.ref_error;
    EXPECT_LT(r.max_residual, 1e-12);
    ASSERT_EQ(r.max_integral_drift.size(), 1u);
    EXPECT_LT(r.max_integral_drift[0].second, 1e-10);
    std::string kicks;
    for (const auto& [name, value] : r.extra)
      if (name == "newton_kicks") kicks = value;
    EXPECT_EQ(kicks, std::to_string(r.steps));
  }
  EXPECT_NEAR(error[0] / error[1], 4.0, 0.4) << error[0] << " " << error[1];
}

}  // namespace
}  // namespace cstab

// The ball in a bowl (Braun-Goldfarb Part II, Sec. 3.1):
//  - mass matrix and forces against an independent Lagrangian (the
//    kinetic energy of the centre written in Cartesian form) by
//    polarization and finite differences,
//  - constraint Jacobians, acceleration terms and the energy gradient (AD)
//    against finite differences; the rolling rows against the velocity of
//    the contact point written with omega,
//  - the consistent initial data on all 9 constraints, to round-off,
//  - the Newton-Euler model against the constrained dynamics, and its
//    first integrals along the reference,
//  - an accurate constrained run against the reference at t = 10.
// Suites named BallRegression* carry the `regression` label, BallSlow*
// `slow`; the rest are `unit`.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "linalg/dense.hpp"
#include "methods/mechanical.hpp"
#include "problems/ball/ball.hpp"
#include "problems/registry.hpp"

namespace cstab {
namespace {

using Q12 = Vec<double, 12>;
using M12 = Eigen::Matrix<double, 12, 12>;
using V3 = Eigen::Vector3d;

const BallParameters kP;
const BallMechanical kMech(kP);

// ---- an independent Lagrangian -------------------------------------------
// Centre c(q) = rho (cos a cos b, cos a sin b, -sin a) written out (not via
// the model's basis), T = 1/2 m |dc/dt|^2 + 1/2 (I/2) sum_i |e_i'|^2,
// V = m g c_z. dc/dt by central differences along v (c is smooth; exact
// enough at h = 1e-4 with the 5-point stencil).
V3 centre_of(const Q12& q) {
  return q(0) * V3(std::cos(q(1)) * std::cos(q(2)), std::cos(q(1)) * std::sin(q(2)), -std::sin(q(1)));
}
V3 centre_velocity(const Q12& q, const Q12& v) {
  const double h = 1e-4;
  return (-centre_of(q + 2 * h * v) + 8 * centre_of(q + h * v) - 8 * centre_of(q - h * v) +
          centre_of(q - 2 * h * v)) /
         (12 * h);
}
double kinetic(const Q12& q, const Q12& v) {
  double rot = 0;
  for (int i = 3; i < 12; ++i) rot += v(i) * v(i);
  return 0.5 * kP.m * centre_velocity(q, v).squaredNorm() + 0.5 * (0.5 * kP.inertia()) * rot;
}
double potential(const Q12& q) { return kP.m * kP.g * centre_of(q)(2); }

// T is quadratic in v: M_ij by polarization.
M12 independent_mass(const Q12& q) {
  M12 M;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      const Q12 ei = Q12::Unit(i), ej = Q12::Unit(j);
      M(i, j) = kinetic(q, ei + ej) - kinetic(q, ei) - kinetic(q, ej);
      if (i == j) M(i, j) = 2 * kinetic(q, ei);
    }
  return M;
}

template <class F>
Q12 gradient_fd(const F& f, const Q12& x, double h = 1e-5) {
  Q12 g;
  for (int i = 0; i < 12; ++i) {
    const Q12 e = Q12::Unit(i) * h;
    g(i) = (-f(x + 2 * e) + 8 * f(x + e) - 8 * f(x - e) + f(x - 2 * e)) / (12 * h);
  }
  return g;
}

// Random states: a random rotation for the axes, random angles away from
// the poles of the spherical coordinates, random rates.
struct State {
  Q12 q, v;
};
State random_state(std::mt19937& rng, bool on_manifold) {
  std::uniform_real_distribution<double> u(-1, 1);
  State s;
  s.q(0) = kP.rc() * (on_manifold ? 1.0 : 1.0 + 0.05 * u(rng));
  s.q(1) = 0.8 * u(rng) + 0.5;
  s.q(2) = 3 * u(rng);
  Eigen::Quaterniond quat(u(rng), u(rng), u(rng), u(rng));
  quat.normalize();
  const Eigen::Matrix3d R = quat.toRotationMatrix();
  const V3 w(u(rng), u(rng), u(rng));
  s.v(0) = on_manifold ? 0.0 : 0.3 * u(rng);
  s.v(1) = u(rng);
  s.v(2) = u(rng);
  for (int i = 0; i < 3; ++i) {
    V3 e = R.col(i);
    V3 ed = w.cross(e);
    if (!on_manifold) {
      e += 0.05 * V3(u(rng), u(rng), u(rng));
      ed += 0.2 * V3(u(rng), u(rng), u(rng));
    }
    s.q.segment<3>(3 + 3 * i) = e;
    s.v.segment<3>(3 + 3 * i) = ed;
  }
  return s;
}

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

// ---- mass matrix, forces ---------------------------------------------------

TEST(BallModel, MassMatrixMatchesIndependentLagrangian) {
  std::mt19937 rng(1);
  for (int k = 0; k < 6; ++k) {
    const State s = random_state(rng, k % 2 == 0);
    M12 M;
    kMech.mass(0.0, s.q, M);
    const M12 Mi = independent_mass(s.q);
    EXPECT_LT(max_abs(M - Mi), 1e-8 * (1 + max_abs(Mi))) << "state " << k;
    // The energy law is 1/2 v^T M v + V.
    EXPECT_NEAR(kMech.energy(0.0, s.q, s.v), kinetic(s.q, s.v) + potential(s.q), 1e-8);
  }
}

// Lagrange: M a = dT/dq - d/dt(dT/dv)|_{a=0} - dV/dq + constraint forces, so
// with M_indep(q) v = dT/dv: Q = dT/dq - d/ds[M(q + s v) v] - dV/dq.
TEST(BallModel, ForcesMatchLagrangeEquations) {
  std::mt19937 rng(2);
  for (int k = 0; k < 6; ++k) {
    const State s = random_state(rng, k % 2 == 0);
    const Q12 dTdq = gradient_fd([&](const Q12& x) { return kinetic(x, s.v); }, s.q, 1e-3);
    const Q12 dVdq = gradient_fd([&](const Q12& x) { return potential(x); }, s.q, 1e-3);
    const double h = 1e-3;
    auto p = [&](double a) { Q12 r = independent_mass(s.q + a * s.v) * s.v; return r; };
    const Q12 ddt = (-p(2 * h) + 8 * p(h) - 8 * p(-h) + p(-2 * h)) / (12 * h);
    const Q12 expected = dTdq - ddt - dVdq;
    Q12 Q;
    kMech.forces(0.0, s.q, s.v, Q);
    EXPECT_LT((Q - expected).lpNorm<Eigen::Infinity>(), 1e-6 * (1 + expected.lpNorm<Eigen::Infinity>()))
        << "state " << k << "\nQ        = " << Q.transpose() << "\nexpected = " << expected.transpose();
  }
}

// ---- constraints -----------------------------------------------------------

Vec<double, 7> phi_of(const Q12& q) {
  Vec<double, 7> f;
  kMech.holonomic(0.0, q, f);
  return f;
}
Vec<double, 2> psi_of(const Q12& q, const Q12& v) {
  Vec<double, 2> f;
  kMech.nonholonomic(0.0, q, v, f);
  return f;
}

TEST(BallModel, ConstraintTermsMatchFiniteDifferences) {
  std::mt19937 rng(3);
  for (int k = 0; k < 6; ++k) {
    const State s = random_state(rng, k % 2 == 0);
    MechanicalTerms<BallMechanical> terms;
    terms.evaluate(kMech, 0.0, s.q, s.v, true);
    const double h = 1e-4;
    // Rows: dPhi/dq and dPsi/dv.
    for (int j = 0; j < 12; ++j) {
      const Q12 e = Q12::Unit(j) * h;
      const Vec<double, 7> dphi = (-phi_of(s.q + 2 * e) + 8 * phi_of(s.q + e) - 8 * phi_of(s.q - e) +
                                   phi_of(s.q - 2 * e)) / (12 * h);
      const Vec<double, 2> dpsi = (-psi_of(s.q, s.v + 2 * e) + 8 * psi_of(s.q, s.v + e) -
                                   8 * psi_of(s.q, s.v - e) + psi_of(s.q, s.v - 2 * e)) / (12 * h);
      for (int i = 0; i < 7; ++i) EXPECT_NEAR(terms.A(i, j), dphi(i), 1e-9) << "row " << i << " col " << j;
      for (int i = 0; i < 2; ++i) EXPECT_NEAR(terms.A(7 + i, j), dpsi(i), 1e-9) << "row " << 7 + i << " col " << j;
    }
    // Acceleration-level terms: gamma = d^2/ds^2 Phi(q + s v) and
    // d/ds Psi(q + s v, v) (v frozen).
    const Vec<double, 7> g_phi =
        (-phi_of(s.q + 2 * h * s.v) + 16 * phi_of(s.q + h * s.v) - 30 * phi_of(s.q) +
         16 * phi_of(s.q - h * s.v) - phi_of(s.q - 2 * h * s.v)) / (12 * h * h);
    const Vec<double, 2> g_psi = (-psi_of(s.q + 2 * h * s.v, s.v) + 8 * psi_of(s.q + h * s.v, s.v) -
                                  8 * psi_of(s.q - h * s.v, s.v) + psi_of(s.q - 2 * h * s.v, s.v)) / (12 * h);
    for (int i = 0; i < 7; ++i) EXPECT_NEAR(terms.gamma(i), g_phi(i), 1e-5) << "gamma " << i;
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(terms.gamma(7 + i), g_psi(i), 1e-8) << "gamma " << 7 + i;
    // Energy gradient in v and the free rate along (q + s v).
    auto E = [&](const Q12& q, const Q12& v) { return kMech.energy(0.0, q, v); };
    const Q12 dEdv = gradient_fd([&](const Q12& x) { return E(s.q, x); }, s.v);
    EXPECT_LT((terms.energy_grad_v - dEdv).lpNorm<Eigen::Infinity>(), 1e-8);
    const double rate = (-E(s.q + 2 * h * s.v, s.v) + 8 * E(s.q + h * s.v, s.v) - 8 * E(s.q - h * s.v, s.v) +
                         E(s.q - 2 * h * s.v, s.v)) / (12 * h);
    EXPECT_NEAR(terms.energy_rate_free, rate, 1e-7);
  }
}

// On the manifold (e_i orthonormal, e_i' = omega x e_i) the rolling rows are
// the e_alpha and e_beta components of the contact point's velocity
// v_C + omega x (r e_rho), written here with omega.
TEST(BallModel, RollingRowsAreContactPointVelocity) {
  std::mt19937 rng(4);
  for (int k = 0; k < 8; ++k) {
    const State s = random_state(rng, true);
    // Recover omega from the axes: omega = 1/2 sum e_i x e_i'.
    V3 w = V3::Zero();
    for (int i = 0; i < 3; ++i) w += 0.5 * V3(s.q.segment<3>(3 + 3 * i)).cross(V3(s.v.segment<3>(3 + 3 * i)));
    const V3 c = centre_of(s.q);
    const V3 er = c / c.norm();
    const V3 vc = centre_velocity(s.q, s.v);
    const V3 vp = vc + w.cross(kP.r * er);
    // e_alpha = d e_rho/d alpha, e_beta = d e_rho/d beta / cos alpha (written out).
    const double a = s.q(1), b = s.q(2);
    const V3 ea(-std::sin(a) * std::cos(b), -std::sin(a) * std::sin(b), -std::cos(a));
    const V3 eb(-std::sin(b), std::cos(b), 0);
    const Vec<double, 2> psi = psi_of(s.q, s.v);
    EXPECT_NEAR(psi(0), ea.dot(vp), 1e-9);
    EXPECT_NEAR(psi(1), eb.dot(vp), 1e-9);
    EXPECT_NEAR(er.dot(vp), s.v(0), 1e-9);  // the left-out row repeats rhodot
  }
}

TEST(BallModel, ConsistentInitialDataSatisfiesAllConstraints) {
  Q12 q, v;
  kMech.initial_state(q, v);
  const Vec<double, 7> phi = phi_of(q);
  const Vec<double, 2> psi = psi_of(q, v);
  EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-15);
  EXPECT_LT(psi.lpNorm<Eigen::Infinity>(), 1e-14);
  // Velocity level of the holonomic rows too.
  MechanicalTerms<BallMechanical> terms;
  terms.evaluate_velocity(kMech, 0.0, q, v);
  EXPECT_LT(terms.velocity.lpNorm<Eigen::Infinity>(), 1e-14);
  // The constraint rows have full rank (9).
  EXPECT_EQ(linalg::rank_of(terms.A), 9);
  // The paper's numbers: rho = 7, alpha = pi/4, alphadot = 0.5, betadot = 1.
  EXPECT_EQ(q(0), 7.0);
  EXPECT_DOUBLE_EQ(q(1), std::acos(-1.0) / 4);
  EXPECT_EQ(v(1), 0.5);
  EXPECT_EQ(v(2), 1.0);
  // omega(0) has omega_rho = 1.
  Ball ball;
  std::vector<double> c(24), fi(2);
  for (int i = 0; i < 12; ++i) c[i] = q(i), c[12 + i] = v(i);
  ball.first_integrals(0.0, c.data(), fi.data());
  EXPECT_NEAR(fi[0], 1.0, 1e-15);
}

// ---- the Newton-Euler model ------------------------------------------------

using Y = Vec<double, BallNewtonEuler::kStates>;

std::vector<double> canonical_of(const BallNewtonEuler& ne, const Y& y) {
  std::vector<double> c(24);
  ne.to_canonical(0.0, y, c.data());
  return c;
}

TEST(BallNewtonEuler, InitialStateMapsToTheMechanicalInitialState) {
  Ball ball;
  Y y;
  ball.minimal().initial_state(y);
  const auto c = canonical_of(ball.minimal(), y);
  Q12 q, v;
  kMech.initial_state(q, v);
  for (int i = 0; i < 12; ++i) {
    EXPECT_NEAR(c[i], q(i), 1e-15) << ball.info().coordinates[i];
    EXPECT_NEAR(c[12 + i], v(i), 1e-14) << ball.info().coordinates[12 + i];
  }
}

// The accelerations of the constrained mechanical system (index-1 form,
// method `none`) equal the time derivative of the Newton-Euler state mapped
// to canonical coordinates: the two formulations have the same dynamics.
TEST(BallNewtonEuler, MatchesTheConstrainedMechanicalDynamics) {
  Ball ball;
  const auto& ne = ball.minimal();
  const Problem& problem = find_problem("ball");
  auto none = problem.make("none", "", Params::resolve(problem.method_params("none", ""), {}, "none"));
  Y y;
  ne.initial_state(y);
  // States along the motion (a few explicit steps of the NE ODE are enough
  // to leave the special initial configuration).
  for (int k = 0; k < 4; ++k) {
    Y dy;
    ne.rhs(0.0, y, dy);
    const double h = 1e-4;
    const auto cp2 = canonical_of(ne, y + 2 * h * dy), cp1 = canonical_of(ne, y + h * dy);
    const auto cm1 = canonical_of(ne, y - h * dy), cm2 = canonical_of(ne, y - 2 * h * dy);
    const auto c = canonical_of(ne, y);
    std::vector<double> f(24);
    ASSERT_TRUE(none->rhs(0.0, c.data(), f.data()));
    for (int i = 0; i < 24; ++i) {
      const double d = (-cp2[i] + 8 * cp1[i] - 8 * cm1[i] + cm2[i]) / (12 * h);
      EXPECT_NEAR(f[i], d, 1e-7 * (1 + std::abs(d))) << "state " << k << " " << problem.info().coordinates[i];
    }
    for (int s = 0; s < 50; ++s) {  // advance ~0.5 s (RK2 is enough to move on)
      Y k1, k2;
      ne.rhs(0.0, y, k1);
      ne.rhs(0.0, y + 0.005 * k1, k2);
      y += 0.01 * k2;
    }
  }
}

TEST(BallNewtonEuler, FirstIntegralsConstantAlongTheReference) {
  Ball ball;
  std::vector<double> c0(24), c(24), fi0(2), fi(2);
  Y y;
  ball.minimal().initial_state(y);
  ball.minimal().to_canonical(0.0, y, c0.data());
  const double e0 = ball.energy(0.0, c0.data());
  ball.first_integrals(0.0, c0.data(), fi0.data());
  EXPECT_NEAR(fi0[1], 0.5 + 2.0 / 49.0 * std::sin(std::acos(-1.0) / 4), 1e-15);
  for (double t : {1.0, 5.0, 10.0, 37.0, 100.0}) {
    ASSERT_TRUE(ball.reference(t, c.data()));
    EXPECT_NEAR(ball.energy(t, c.data()), e0, 1e-10) << "t = " << t;
    ball.first_integrals(t, c.data(), fi.data());
    EXPECT_NEAR(fi[0], fi0[0], 1e-11) << "spin, t = " << t;
    EXPECT_NEAR(fi[1], fi0[1], 1e-11) << "eps, t = " << t;
    // The constraints hold by construction on the mapped state.
    Q12 q, v;
    for (int i = 0; i < 12; ++i) q(i) = c[i], v(i) = c[12 + i];
    EXPECT_LT(phi_of(q).lpNorm<Eigen::Infinity>(), 1e-14) << "t = " << t;
    EXPECT_LT(psi_of(q, v).lpNorm<Eigen::Infinity>(), 1e-13) << "t = " << t;
    // The motion is non-trivial: beta advances, alpha stays away from the poles.
    EXPECT_GT(c[1], 0.1);
    EXPECT_LT(c[1], 1.5);
  }
  EXPECT_GT(c[2], 10.0);  // beta(100): many revolutions, unwrapped
}

// The reference does not depend on the integrator: GSL rk8pd at 1e-13
// against msadams (different scheme) at 1e-13, through the harness.
TEST(BallRegression, ReferenceAgreesWithAnotherIntegrator) {
  const Problem& problem = find_problem("ball");
  RunConfig cfg;
  cfg.problem = "ball";
  cfg.method = "minimal";
  cfg.integrator = "msadams";
  cfg.step.rtol = cfg.step.atol = 1e-13;
  cfg.t_end = 10;
  cfg.ref_time = 10;
  cfg.write_series = false;
  const RunResult res = run_case(problem, cfg, "");
  ASSERT_EQ(res.status, "ok") << res.reason;
  EXPECT_LT(res.ref_error, 1e-9);
  EXPECT_LT(res.max_residual, 1e-13);
}

// ---- constrained runs against the reference --------------------------------

struct Agreement {
  double centre, omega;
  RunResult result;
};
Agreement run_against_reference(const std::string& method, const std::string& integrator, double tol,
                                std::vector<std::pair<std::string, std::string>> params, double t) {
  const Problem& problem = find_problem("ball");
  RunConfig cfg;
  cfg.problem = "ball";
  cfg.method = method;
  cfg.integrator = integrator;
  cfg.step.rtol = cfg.step.atol = tol;
  cfg.params = std::move(params);
  cfg.t_end = t;
  cfg.ref_time = t;
  cfg.write_series = false;
  Agreement a;
  a.result = run_case(problem, cfg, "");
  if (a.result.status != "ok" || a.result.state_at_ref.empty()) {
    a.centre = a.omega = INFINITY;
    return a;
  }
  const double* x = a.result.state_at_ref.data();
  const double* r = a.result.ref_state.data();
  a.centre = (Ball::centre(x) - Ball::centre(r)).lpNorm<Eigen::Infinity>();
  a.omega = (Ball::angular_velocity(x) - Ball::angular_velocity(r)).lpNorm<Eigen::Infinity>();
  return a;
}

TEST(BallRegression, ProjectionAgreesWithReferenceAtTen) {
  const Agreement a = run_against_reference("projection", "rk8pd", 1e-13, {}, 10);
  ASSERT_EQ(a.result.status, "ok") << a.result.reason;
  EXPECT_LT(a.centre, 1e-9);
  EXPECT_LT(a.omega, 1e-9);
  EXPECT_LT(a.result.max_residual, 1e-12);
  EXPECT_LT(a.result.max_energy_drift, 1e-10);
  for (const auto& [name, drift] : a.result.max_integral_drift) EXPECT_LT(drift, 1e-10) << name;
}

TEST(BallRegression, BraunGoldfarbAndPesterevAgreeWithReferenceAtTen) {
  const Agreement bg = run_against_reference("braun-goldfarb", "rk8pd", 1e-12, {{"dt", "1e-2"}}, 10);
  ASSERT_EQ(bg.result.status, "ok") << bg.result.reason;
  EXPECT_LT(bg.centre, 1e-9);
  EXPECT_LT(bg.omega, 1e-9);
  const Agreement pe = run_against_reference("pesterev", "rk8pd", 1e-13, {{"lambda", "50"}}, 10);
  ASSERT_EQ(pe.result.status, "ok") << pe.result.reason;
  EXPECT_LT(pe.centre, 1e-9);
  EXPECT_LT(pe.omega, 1e-9);
}

// The accurate setting over the paper's whole horizon.
TEST(BallRegression, ProjectionAgreesWithReferenceAtHundred) {
  const Agreement a = run_against_reference("projection", "rk8pd", 1e-13, {}, 100);
  ASSERT_EQ(a.result.status, "ok") << a.result.reason;
  EXPECT_LT(a.centre, 1e-6);
  EXPECT_LT(a.omega, 1e-6);
  for (const auto& [name, drift] : a.result.max_integral_drift) EXPECT_LT(drift, 1e-9) << name;
}

// The paper's setting (braun-goldfarb, RK4, dt = h) on a short horizon: the
// residuals stay at a floor that scales like h^2 (the correction's rate 1/dt
// = 1/h makes RK4 lose its order on the correction terms).
TEST(BallRegression, PaperSettingResidualFloorScalesLikeStepSquared) {
  auto run = [](double h) {
    RunConfig cfg;
    cfg.problem = "ball";
    cfg.method = "braun-goldfarb";
    cfg.integrator = "rk4";
    cfg.step.step = h;
    cfg.t_end = 10;
    cfg.write_series = false;
    return run_case(find_problem("ball"), cfg, "");
  };
  const RunResult a = run(1e-2), b = run(5e-3);
  ASSERT_EQ(a.status, "ok") << a.reason;
  ASSERT_EQ(b.status, "ok") << b.reason;
  EXPECT_LT(a.max_residual, 1e-2);
  EXPECT_LT(a.max_energy_drift, 1e-2);
  const double ratio = a.max_residual / b.max_residual;
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 5.0);
}

}  // namespace
}  // namespace cstab

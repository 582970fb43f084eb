// The seven-link biped (Braun-Goldfarb Part II, Sec. 3.2):
//  - the model: hand-written M(q), Q(q, v) against the Lagrangian (AD on M
//    and V) and against finite differences of the segment kinematics; the
//    paper's constraint expressions against the point kinematics;
//  - the AD constraint derivatives (MechanicalTerms) against finite differences;
//  - the exact reference: every constraint at round-off at several times,
//    closed form = Newton from elsewhere, velocities = d/dt of positions;
//  - braun-goldfarb + rk4 from the paper's inconsistent q(0):
//    * with the paper's coupling (correction time dt = step) the residual
//      floor is O(step^2): rk4's order reduction on the stiff correction of
//      the time-driven constraints (5.2e-8 at step 1e-3, not 1e-10);
//    * at step 1e-3 with dt = 0.03 every residual is below 1e-10 within 2 s,
//      and after the transient the motion equals the exact kinematic
//      solution, with the contact abscissae read off the numerical solution,
//      to 1e-8;
//    * braun-goldfarb moves the contacts while it corrects; as step/dt -> 0
//      it lands on the correction flow's end point;
//  - baumgarte (force-based) keeps the contacts of q(0): it converges to
//    reference() itself.
// Suites named BipedRegression* carry the `regression` label.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "methods/mechanical.hpp"
#include "problems/biped/biped.hpp"
#include "problems/registry.hpp"

namespace cstab {
namespace {

using V9 = Vec<double, 9>;
using M9 = Eigen::Matrix<double, 9, 9>;
using BM = BipedMechanical;

// States near the motion: the paper's q(0), random perturbations of it, and
// points of the exact motion, with random velocities.
std::vector<std::pair<V9, V9>> sample_states() {
  const Biped biped;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::pair<V9, V9>> out;
  V9 q0, v0;
  biped.mechanical().initial_state(q0, v0);
  for (int k = 0; k < 4; ++k) {
    V9 dq, v;
    for (int i = 0; i < 9; ++i) {
      dq(i) = 0.2 * u(rng);
      v(i) = 2 * u(rng);
    }
    out.emplace_back(k == 0 ? q0 : V9(q0 + dq), v);
  }
  for (double t : {0.3, 1.1}) {
    std::vector<double> c(18);
    EXPECT_TRUE(biped.reference(t, c.data()));
    out.emplace_back(vmap<9>(c.data()), vmap<9>(c.data() + 9));
  }
  return out;
}

// 5-point central difference of g(s) at s = 0.
template <class G>
auto central(const G& g, double eps = 1e-4) {
  return ((-g(2 * eps) + 8 * g(eps) - 8 * g(-eps) + g(-2 * eps)) / (12 * eps)).eval();
}

// ---------------------------------------------------------------------------

TEST(BipedModel, ParametersAndInconsistency) {
  const BipedParameters p;
  EXPECT_NEAR(p.m_hat + 2 * (p.m_thigh + p.m_shank + p.m_foot), p.body_mass, 1e-12);
  const Biped biped;
  V9 q0, v0;
  biped.mechanical().initial_state(q0, v0);
  Vec<double, 7> phi;
  biped.mechanical().holonomic(0.0, q0, phi);
  // Slightly inconsistent: millimetres and milliradians, not more.
  EXPECT_GT(phi.lpNorm<Eigen::Infinity>(), 1e-3);
  EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 5e-3);
  // The hip lies at x = 0 within 2 mm at t = 0 ((x, y) is the HAT centre of mass).
  EXPECT_NEAR(biped.mechanical().point(q0, biped.mechanical().hip())(0), 0.0, 2e-3);
  // Velocity level: v = 0 and Phi_t(0) = 0, so consistent.
  MechanicalTerms<BM> terms;
  terms.evaluate_velocity(biped.mechanical(), 0.0, q0, v0);
  EXPECT_EQ(terms.velocity.lpNorm<Eigen::Infinity>(), 0.0);
}

// The paper's Phi_1, Phi_2 are the heights of heel 1 and toe 2; Psi is the
// time derivative of their abscissae.
TEST(BipedModel, ConstraintsMatchThePointKinematics) {
  const Biped biped;
  const BM& m = biped.mechanical();
  for (const auto& state : sample_states()) {
    const V9& q = state.first;  // named, not bound: clang 14 lambdas cannot capture bindings
    const V9& v = state.second;
    Vec<double, 7> phi;
    m.holonomic(0.37, q, phi);
    EXPECT_NEAR(phi(0), m.point(q, m.heel(0))(1), 1e-14);
    EXPECT_NEAR(phi(1), m.point(q, m.toe(1))(1), 1e-14);
    Vec<double, 2> psi;
    m.nonholonomic(0.0, q, v, psi);
    const Vec<double, 2> d = central([&](double s) { return m.contact_abscissae(V9(q + s * v)); });
    EXPECT_NEAR(psi(0), d(0), 1e-9);
    EXPECT_NEAR(psi(1), d(1), 1e-9);
  }
}

// v^T M v = sum_k m_k |d/dt com_k|^2 + I_k theta_k'^2, with the centre-of-mass
// velocities by finite differences of the kinematics.
TEST(BipedModel, MassMatrixIsTheKineticEnergy) {
  const Biped biped;
  const BM& m = biped.mechanical();
  for (const auto& state : sample_states()) {
    const V9& q = state.first;  // named, not bound: clang 14 lambdas cannot capture bindings
    const V9& v = state.second;
    M9 M;
    m.mass(0.0, q, M);
    EXPECT_LT((M - M.transpose()).norm(), 1e-12);
    EXPECT_EQ(Eigen::LLT<M9>(M).info(), Eigen::Success);
    double twoT = 0;
    for (int k = 0; k < BM::kBodies; ++k) {
      const auto c = m.body_com(k);
      const Vec<double, 2> rdot = central([&](double s) { return m.point(V9(q + s * v), c); });
      twoT += m.body_mass(k) * rdot.squaredNorm() + m.body_inertia(k) * std::pow(v(BM::body_angle(k)), 2);
    }
    EXPECT_NEAR(v.dot(M * v), twoT, 1e-8 * twoT);
  }
}

// Q = -C(q, v) - grad V with C_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) v_j v_k
// (dM by AD) and V = g sum_k m_k y_k.
TEST(BipedModel, ForcesAreLagrangesEquations) {
  const Biped biped;
  const BM& m = biped.mechanical();
  using D = ad::Dual<9>;
  for (const auto& state : sample_states()) {
    const V9& q = state.first;  // named, not bound: clang 14 lambdas cannot capture bindings
    const V9& v = state.second;
    Vec<D, 9> qd;
    for (int i = 0; i < 9; ++i) qd(i) = D(q(i), 9, i);
    Eigen::Matrix<D, 9, 9> Md;
    m.mass(D(0.0), qd, Md);
    D V(0.0);
    for (int k = 0; k < BM::kBodies; ++k) V += m.body_mass(k) * biped.parameters().g * m.point(qd, m.body_com(k))(1);
    std::array<M9, 9> dM;
    for (int k = 0; k < 9; ++k)
      for (int i = 0; i < 9; ++i)
        for (int j = 0; j < 9; ++j) dM[k](i, j) = Md(i, j).derivatives()(k);
    V9 Qlag = -V.derivatives();
    for (int i = 0; i < 9; ++i) {
      double c = 0;
      for (int k = 0; k < 9; ++k) c += dM[k].row(i).dot(v) * v(k);
      c -= 0.5 * v.dot(dM[i] * v);
      Qlag(i) -= c;
    }
    V9 Q;
    m.forces(0.0, q, v, Q);
    EXPECT_LT((Q - Qlag).lpNorm<Eigen::Infinity>(), 1e-10 * (1 + Qlag.lpNorm<Eigen::Infinity>()))
        << "Q = " << Q.transpose() << "\nLagrange: " << Qlag.transpose();
  }
}

// The AD terms every mechanical method uses: J, Phi_t, G, and the
// acceleration-level gamma, against finite differences.
TEST(BipedModel, ConstraintDerivativesMatchFiniteDifferences) {
  const Biped biped;
  const BM& m = biped.mechanical();
  for (const auto& state : sample_states()) {
    const V9& q = state.first;  // named, not bound: clang 14 lambdas cannot capture bindings
    const V9& v = state.second;
    for (double t : {0.0, 0.23, 1.4}) {
      MechanicalTerms<BM> terms;
      terms.evaluate(m, t, q, v, false);
      auto phi = [&](double tt, const V9& qq) {
        Vec<double, 7> f;
        m.holonomic(tt, qq, f);
        return f;
      };
      auto psi = [&](double tt, const V9& qq, const V9& vv) {
        Vec<double, 2> f;
        m.nonholonomic(tt, qq, vv, f);
        return f;
      };
      for (int j = 0; j < 9; ++j) {
        const V9 e = V9::Unit(j);
        const Vec<double, 7> dphi = central([&](double s) { return phi(t, V9(q + s * e)); });
        const Vec<double, 2> dpsi = central([&](double s) { return psi(t, q, V9(v + s * e)); });
        for (int i = 0; i < 7; ++i) EXPECT_NEAR(terms.A(i, j), dphi(i), 1e-9);
        for (int i = 0; i < 2; ++i) EXPECT_NEAR(terms.A(7 + i, j), dpsi(i), 1e-9);
      }
      const Vec<double, 7> phit = central([&](double s) { return phi(t + s, q); });
      EXPECT_LT((terms.phi_t - phit).lpNorm<Eigen::Infinity>(), 1e-9);
      // gamma: d/ds of the velocity residual along (t + s, q + s v) with v frozen.
      const Vec<double, 7> g_h = central([&](double s) {
        MechanicalTerms<BM> tt;
        tt.evaluate_velocity(m, t + s, V9(q + s * v), v);
        return Vec<double, 7>(tt.velocity.head<7>());
      });
      const Vec<double, 2> g_n = central([&](double s) { return psi(t + s, V9(q + s * v), v); });
      EXPECT_LT((terms.gamma.head<7>() - g_h).lpNorm<Eigen::Infinity>(), 1e-7 * (1 + g_h.norm()));
      EXPECT_LT((terms.gamma.tail<2>() - g_n).lpNorm<Eigen::Infinity>(), 1e-7 * (1 + g_n.norm()));
    }
  }
}

// ---------------------------------------------------------------------------

TEST(BipedReference, ConsistentVersionsOfTheInitialData) {
  const Biped biped;
  V9 q0, v0;
  biped.mechanical().initial_state(q0, v0);
  for (const V9& qc : {biped.projected_initial_configuration(), biped.flow_initial_configuration()}) {
    Vec<double, 7> phi;
    biped.mechanical().holonomic(0.0, qc, phi);
    EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-14);
    EXPECT_LT((qc - q0).lpNorm<Eigen::Infinity>(), 1e-2);  // the inconsistency is small
  }
  // Projection: KKT, M(q0) (qp - q0) lies in the row space of J(qp).
  const V9& qp = biped.projected_initial_configuration();
  MechanicalTerms<BM> terms;
  terms.evaluate_position(biped.mechanical(), 0.0, qp);
  const Eigen::Matrix<double, 7, 9> J = terms.A.topRows<7>();
  M9 W;
  biped.mechanical().mass(0.0, q0, W);
  const V9 g = W * (qp - q0);
  const V9 in_rows = J.transpose() * (J * J.transpose()).ldlt().solve(J * g);
  EXPECT_LT((g - in_rows).norm(), 1e-12 * (1 + g.norm()));
  // The flow end point agrees with the projection to second order in the
  // inconsistency (|Phi_0|^2 ~ 1.4e-5) but not exactly.
  const V9 dqf = biped.flow_initial_configuration() - qp;
  EXPECT_LT(dqf.lpNorm<Eigen::Infinity>(), 5e-5);
  EXPECT_GT(dqf.lpNorm<Eigen::Infinity>(), 1e-7);
  // The reference constants are the contact abscissae of q(0).
  EXPECT_EQ(biped.mechanical().contact_abscissae(q0), biped.reference_constants());
  EXPECT_EQ(biped.mechanical().contact_abscissae(biped.flow_initial_configuration()), biped.flow_constants());
}

TEST(BipedReference, SatisfiesEveryConstraintToRoundOff) {
  const Biped biped;
  const BM& m = biped.mechanical();
  const Vec<double, 2> X = biped.reference_constants();
  for (double t : {0.0, 0.25, 0.5, 1.0, 1.37, 10.0, 55.5, 100.0}) {
    std::vector<double> c(18);
    ASSERT_TRUE(biped.reference(t, c.data())) << "t = " << t;
    const V9 q = vmap<9>(c.data()), v = vmap<9>(c.data() + 9);
    MechanicalTerms<BM> terms;
    terms.evaluate_velocity(m, t, q, v);
    EXPECT_LT(terms.phi.lpNorm<Eigen::Infinity>(), 1e-14) << "t = " << t;
    EXPECT_LT(terms.velocity.lpNorm<Eigen::Infinity>(), 1e-13) << "t = " << t;  // J v + Phi_t and Psi
    const Vec<double, 2> xc = m.contact_abscissae(q);
    EXPECT_LT((xc - X).lpNorm<Eigen::Infinity>(), 1e-14) << "t = " << t;
    // Velocities are the time derivative of the exact configuration.
    const V9 dq = central(
        [&](double s) {
          V9 qs;
          EXPECT_TRUE(biped.exact_configuration(t + s, X, qs));
          return qs;
        },
        1e-3);
    EXPECT_LT((dq - v).lpNorm<Eigen::Infinity>(), 1e-9) << "t = " << t;
  }
}

// Newton on the 9 equations from a rough start lands on the closed form.
TEST(BipedReference, NewtonAgreesWithTheClosedForm) {
  const Biped biped;
  const Vec<double, 2> X = biped.reference_constants();
  V9 q_prev;
  ASSERT_TRUE(biped.closed_form_configuration(0.0, X, q_prev));
  for (int k = 1; k <= 40; ++k) {
    const double t = 0.05 * k;
    V9 q_cf, q_n = q_prev;  // start from the configuration 0.05 s earlier
    ASSERT_TRUE(biped.closed_form_configuration(t, X, q_cf));
    double res = 1;
    ASSERT_TRUE(biped.newton(t, X, q_n, &res)) << "t = " << t;
    EXPECT_LT(res, 1e-14);
    EXPECT_LT((q_n - q_cf).lpNorm<Eigen::Infinity>(), 1e-13) << "t = " << t;
    q_prev = q_n;
  }
}

// The exact motion is periodic with period 2 pi / omega = 2 s.
TEST(BipedReference, MotionIsPeriodic) {
  const Biped biped;
  std::vector<double> a(18), b(18);
  for (double t : {0.0, 0.7, 1.3}) {
    ASSERT_TRUE(biped.reference(t, a.data()));
    ASSERT_TRUE(biped.reference(t + 2.0, b.data()));
    for (int i = 0; i < 18; ++i) EXPECT_NEAR(a[i], b[i], 1e-12) << i;
  }
}

// ---------------------------------------------------------------------------
// braun-goldfarb + rk4 from the paper's q(0), v(0) = 0.

struct Trajectory {
  std::vector<double> t;
  std::vector<std::vector<double>> y;
  std::vector<double> max_residual;  // over all 9 rows
  double floor(double from) const {  // max residual on [from, end]
    double f = 0;
    for (size_t k = 0; k < t.size(); ++k)
      if (t[k] >= from - 1e-12) f = std::max(f, max_residual[k]);
    return f;
  }
  // First grid time from which the residual stays below `level`.
  double below_from(double level) const {
    for (size_t k = t.size(); k-- > 0;)
      if (max_residual[k] >= level) return k + 1 < t.size() ? t[k + 1] : -1;
    return t.front();
  }
};

// A method on the registered biped (its pair is compiled once, in the
// library: instantiating the methods here again took this unit to 1 GB).
std::unique_ptr<Formulation> make_biped(const std::string& method,
                                        const std::vector<std::pair<std::string, std::string>>& given) {
  const Problem& p = find_problem("biped");
  return p.make(method, "mechanical", Params::resolve(p.method_params(method, "mechanical"), given, method));
}

// rk4 with fixed `step`, correction time scale `dt`, no energy correction.
Trajectory run_braun_goldfarb(double step, double dt, double t_end) {
  const auto formulation = make_biped("braun-goldfarb", {{"dt", format_exact(dt)}, {"energy", "0"}, {"tol", "1e-6"}});
  Formulation& form = *formulation;
  auto integ = make_integrator("rk4", StepSettings{step, 0, 0});
  std::vector<double> y0(18), r(9);
  form.initial_state(y0.data());
  integ->start(form, 0.0, y0.data());
  Trajectory tr;
  auto record = [&]() {
    tr.t.push_back(integ->t());
    tr.y.emplace_back(integ->y(), integ->y() + 18);
    form.residuals(integ->t(), integ->y(), r.data());
    double mx = 0;
    for (double x : r) mx = std::max(mx, std::abs(x));
    tr.max_residual.push_back(mx);
  };
  record();
  while (integ->t() < t_end - 0.5 * step) {
    EXPECT_EQ(integ->step(t_end + step), StepOutcome::kOk) << integ->failure_reason();
    record();
  }
  return tr;
}

// The paper's setting couples the correction time to the step (dt = step).
// The floor is then O(step^2): rk4 has stage order 1, and with h/dt = 1 the
// correction of the time-driven rows (knee, trunk, feet: theta_i - g(t)) is
// stiff; the scalar model y' = g' - (y - g)/h reproduces the floor digit for
// digit (5.16e-6 at h = 1e-2 for g = pi/10 (1 - cos(pi t))).
TEST(BipedRegression, PaperCouplingFloorIsSecondOrderInTheStep) {
  const Trajectory a = run_braun_goldfarb(2e-3, 2e-3, 4.0), b = run_braun_goldfarb(1e-3, 1e-3, 4.0);
  const double fa = a.floor(2.0), fb = b.floor(2.0);
  EXPECT_GT(fb, 3e-8);
  EXPECT_LT(fb, 8e-8);
  EXPECT_NEAR(std::log2(fa / fb), 2.0, 0.15);
  // The transient is over within 0.1 s: within a factor 2 of the floor.
  EXPECT_LT(b.below_from(2 * fb), 0.1);
  std::cout << "[ biped ] dt = step: floor " << fa << " (2e-3), " << fb << " (1e-3)\n";
}

// step 1e-3, dt = 0.03: residuals below 1e-10 within 2 s and the exact
// motion after the transient.
TEST(BipedRegression, BraunGoldfarbRecoversAndFollowsTheExactMotion) {
  const double step = 1e-3, t_end = 12.0;
  const Trajectory tr = run_braun_goldfarb(step, 0.03, t_end);
  const Biped biped;
  ASSERT_GT(tr.max_residual.front(), 1e-3);  // the start is inconsistent
  const double t_recovered = tr.below_from(1e-10), worst_after = tr.floor(2.0);
  EXPECT_LT(worst_after, 1e-10);
  EXPECT_GT(t_recovered, 0);
  EXPECT_LT(t_recovered, 2.0);
  // Integration constants read off the numerical solution at t = 2.
  const size_t k2 = size_t(std::llround(2.0 / step));
  ASSERT_NEAR(tr.t[k2], 2.0, 1e-9);
  const Vec<double, 2> X = biped.mechanical().contact_abscissae(V9(vmap<9>(tr.y[k2].data())));
  // The correction moved the contacts by ~5 mm, to about the correction
  // flow's end point (at dt = 0.03 the motion proceeds during the transient
  // and shifts them a further ~1e-5).
  EXPECT_GT((X - biped.reference_constants()).lpNorm<Eigen::Infinity>(), 1e-3);
  EXPECT_LT((X - biped.flow_constants()).lpNorm<Eigen::Infinity>(), 3e-5);
  // After the transient the whole motion is the exact one for those constants.
  double worst = 0;
  std::vector<double> c(18);
  for (size_t k = k2; k < tr.t.size(); k += 50) {
    ASSERT_TRUE(biped.exact_state(tr.t[k], X, c.data()));
    for (int i = 0; i < 18; ++i) worst = std::max(worst, std::abs(tr.y[k][i] - c[i]));
  }
  EXPECT_LT(worst, 1e-8);
  std::cout << "[ biped ] step 1e-3, dt 0.03: residual < 1e-10 from t = " << t_recovered
            << " s, max residual on [2, " << t_end << "] = " << worst_after
            << ", max |y - exact(X from t = 2)| = " << worst
            << ", X - X_flow = " << (X - biped.flow_constants()).transpose() << "\n";
}

// As step/dt -> 0 and dt -> 0 the transient lands on the correction flow's
// end point: O(dt^2) away.
TEST(BipedRegression, TransientLandsOnTheReferenceContacts) {
  const Biped biped;
  std::vector<double> dev;
  for (double dt : {4e-3, 2e-3}) {
    const Trajectory tr = run_braun_goldfarb(dt / 20, dt, 30 * dt);
    const Vec<double, 2> X = biped.mechanical().contact_abscissae(V9(vmap<9>(tr.y.back().data())));
    dev.push_back((X - biped.flow_constants()).lpNorm<Eigen::Infinity>());
  }
  EXPECT_LT(dev[1], 1e-7);
  EXPECT_NEAR(std::log2(dev[0] / dev[1]), 2.0, 0.3);
}

// Force-based stabilization keeps Psi = 0 and with it the contacts of q(0):
// baumgarte converges to reference() itself.
TEST(BipedRegression, BaumgarteKeepsTheInitialContacts) {
  const Biped biped;
  const auto formulation = make_biped("baumgarte", {{"alpha", "10"}, {"beta", "10"}, {"gamma", "10"}});
  Formulation& form = *formulation;
  auto integ = make_integrator("rk4", StepSettings{1e-3, 0, 0});
  std::vector<double> y(18), c(18);
  form.initial_state(y.data());
  integ->start(form, 0.0, y.data());
  while (integ->t() < 10 - 0.5e-3) ASSERT_EQ(integ->step(11), StepOutcome::kOk) << integ->failure_reason();
  const Vec<double, 2> X = biped.mechanical().contact_abscissae(V9(vmap<9>(integ->y())));
  EXPECT_LT((X - biped.reference_constants()).lpNorm<Eigen::Infinity>(), 1e-10);
  ASSERT_TRUE(biped.reference(integ->t(), c.data()));
  double err = 0;
  for (int i = 0; i < 18; ++i) err = std::max(err, std::abs(integ->y()[i] - c[i]));
  EXPECT_LT(err, 1e-8);
  std::cout << "[ biped ] baumgarte step 1e-3: |y(10) - reference(10)| = " << err << "\n";
}

// The problem is registered and says it has no energy law.
TEST(BipedModel, RegisteredWithoutEnergyLaw) {
  const Problem& p = find_problem("biped");
  EXPECT_FALSE(p.info().has_energy);
  EXPECT_EQ(p.info().coordinates.size(), 18u);
  EXPECT_EQ(p.info().default_t_end, 100);
  EXPECT_EQ(p.info().reference_time, 10);
  for (const char* method : {"braun-goldfarb", "pesterev", "baumgarte", "projection", "none"})
    EXPECT_EQ(p.why_not(method), "") << method;
}

}  // namespace
}  // namespace cstab

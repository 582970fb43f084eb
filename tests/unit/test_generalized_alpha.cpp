// The generalized-alpha family (methods/generalized_alpha.hpp) against what
// the papers prove: second order in positions and velocities (Arnold & Bruls
// 2007), spectral radius rho_inf at h omega -> infinity (Chung & Hulbert
// 1993; HHT: (1 + alpha)/(1 - alpha)), an iteration matrix whose condition
// number the scaling keeps bounded as h -> 0 (Bottasso, Bauchau & Cardona
// 2007) while the plain one grows; and the CLI's answer to bad parameters.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "methods/generalized_alpha.hpp"
#include "problems/registry.hpp"
#include "tests/support/order_util.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

using testing::log_slope;
using testing::tight_reference;

// ---- observed order against the references ----

struct Errors {
  double position = 0, velocity = 0;
};

// Max error over the first `n_pos` canonical coordinates (positions) and the
// rest (velocities) at the reference time, against `ref` (NaN: unscored).
Errors split_errors(const RunResult& r, const std::vector<double>& ref, size_t n_pos) {
  Errors e;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (std::isnan(ref[i])) continue;
    const double d = std::abs(r.state_at_ref[i] - ref[i]);
    (i < n_pos ? e.position : e.velocity) = std::max(i < n_pos ? e.position : e.velocity, d);
  }
  return e;
}

RunResult run_own(const std::string& problem, const std::string& method, double h, double t_end) {
  RunConfig cfg;
  cfg.problem = problem;
  cfg.method = method;
  cfg.integrator = "own";
  cfg.step.step = h;
  cfg.t_end = t_end;
  cfg.ref_time = t_end;
  cfg.write_series = false;
  if (method == "ali3p")
    cfg.params = {{"tol", "1e-13"}, {"iterations", "200"}};
  else
    cfg.params = {{"newton_tol", "1e-13"}, {"newton_iterations", "30"}};
  return run_case(find_problem(problem), cfg, "");
}

struct OrderCase {
  std::string problem;
  double t_end, h_max;  // h from h_max down a decade
};

void expect_second_order(const OrderCase& oc, const std::string& method) {
  const Problem& p = find_problem(oc.problem);
  const size_t n_pos = p.info().coordinates.size() / 2;
  // Positions against the problem's reference; velocities against a tight run
  // where the reference does not publish them.
  const std::vector<double> tight = tight_reference(oc.problem, oc.t_end);
  std::vector<double> hs, pos, vel;
  for (double f : {1.0, 0.5, 0.25, 0.1}) {
    const double h = oc.h_max * f;
    const RunResult r = run_own(oc.problem, method, h, oc.t_end);
    ASSERT_EQ(r.status, "ok") << method << " h = " << h << ": " << r.reason;
    const Errors published = split_errors(r, r.ref_state, n_pos);
    const Errors against_tight = split_errors(r, tight, n_pos);
    hs.push_back(h);
    pos.push_back(published.position);
    vel.push_back(against_tight.velocity);
    std::cout << "[ order    ] " << oc.problem << " " << method << " h = " << h << ": position error "
              << published.position << ", velocity error " << against_tight.velocity << "\n";
  }
  const double position_order = log_slope(hs, pos), velocity_order = log_slope(hs, vel);
  std::cout << "[ order    ] " << oc.problem << " " << method << ": observed order positions " << position_order
            << ", velocities " << velocity_order << "\n";
  EXPECT_GE(position_order, 1.8) << oc.problem << " " << method;
  EXPECT_LE(position_order, 2.2) << oc.problem << " " << method;
  EXPECT_GE(velocity_order, 1.8) << oc.problem << " " << method;
  EXPECT_LE(velocity_order, 2.2) << oc.problem << " " << method;
}

class SecondOrder : public ::testing::TestWithParam<std::string> {};

TEST_P(SecondOrder, SliderCrank) { expect_second_order({"slider-crank", 10, 4e-3}, GetParam()); }
TEST_P(SecondOrder, Andrews) { expect_second_order({"andrews", 0.03, 4e-5}, GetParam()); }

INSTANTIATE_TEST_SUITE_P(GeneralizedAlpha, SecondOrder,
                         ::testing::Values("generalized-alpha", "hht", "generalized-alpha-i2", "ali3p"),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string s = i.param;
                           for (char& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

// ---- spectral radius on a constrained linear oscillator ----

// A unit point mass in the plane on an isotropic spring of stiffness omega^2
// to the origin, constrained to the line x = y: the motion along the line is
// a harmonic oscillator of frequency omega, the constraint force balances
// nothing (lambda = 0).
class ConstrainedOscillator {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = false;
  explicit ConstrainedOscillator(double omega) : k_(omega * omega) {}
  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const { return {{"line", "holonomic", "x - y"}}; }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << 1, 1;
    v.setZero();
  }
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
  template <class S>
  void mass(const S&, const Vec<S, 2>&, Eigen::Matrix<S, 2, 2>& M) const {
    M.setIdentity();
  }
  template <class S>
  void forces(const S&, const Vec<S, 2>& q, const Vec<S, 2>&, Vec<S, 2>& Q) const {
    Q(0) = -k_ * q(0);
    Q(1) = -k_ * q(1);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) - q(1);
  }

 private:
  double k_;
};

// The spectral radius of one step's amplification matrix on the line: the
// map (s, s', a) -> (s, s', a) along e = (1, 1)/sqrt(2), vdot = -omega^2 s
// (the consistent acceleration), from unit inputs (the step is linear).
double spectral_radius(const AlphaCoefficients& c, double h_omega) {
  constexpr double omega = 1e2;
  const double h = h_omega / omega;
  ConstrainedOscillator model(omega);
  AlphaSettings settings;
  settings.coefficients = c;
  settings.newton_tol = 1e-9;
  settings.newton_max_iterations = 30;
  GeneralizedAlphaFormulation<ConstrainedOscillator, false> scheme(model, "test", settings);
  using F = decltype(scheme);
  const Vec<double, 2> e = Vec<double, 2>(1, 1) / std::sqrt(2.0);
  Eigen::Matrix3d G;
  for (int col = 0; col < 3; ++col) {
    Vec<double, F::kDim> y = Vec<double, F::kDim>::Zero();
    const double s = col == 0 ? 1 : 0, sv = col == 1 ? 1 : 0, sa = col == 2 ? 1 : 0;
    y.segment<2>(0) = s * e;
    y.segment<2>(2) = sv * e;
    y.segment<2>(F::kA) = sa * e;
    y.segment<2>(F::kVdot) = -omega * omega * s * e;
    EXPECT_TRUE(scheme.advance(0.0, h, y.data())) << scheme.failure_reason();
    G(0, col) = e.dot(y.segment<2>(0));
    G(1, col) = e.dot(y.segment<2>(2));
    G(2, col) = e.dot(y.segment<2>(F::kA));
    // The motion stays on the line.
    EXPECT_NEAR(y(0) - y(1), 0.0, 1e-12 * (1 + y.segment<2>(0).norm()));
  }
  return Eigen::EigenSolver<Eigen::Matrix3d>(G).eigenvalues().cwiseAbs().maxCoeff();
}

TEST(GeneralizedAlphaSpectralRadius, EqualsRhoInfAtLargeStep) {
  for (double rho : {0.0, 0.5, 0.9, 1.0}) {
    const double r = spectral_radius(AlphaCoefficients::from_rho_inf(rho), 1e4);
    std::cout << "[ spectral ] generalized-alpha rho_inf = " << rho << ": spectral radius at h omega = 1e4: " << r
              << "\n";
    EXPECT_NEAR(r, rho, std::max(0.02 * rho, 0.02)) << "rho_inf = " << rho;
  }
}

TEST(GeneralizedAlphaSpectralRadius, HhtEqualsOnePlusAlphaOverOneMinusAlpha) {
  for (double alpha : {-1.0 / 3.0, -0.2, -0.05, 0.0}) {
    const double expected = (1 + alpha) / (1 - alpha);
    const double r = spectral_radius(AlphaCoefficients::from_hht_alpha(alpha), 1e4);
    std::cout << "[ spectral ] hht alpha = " << alpha << ": spectral radius at h omega = 1e4: " << r
              << " (expected " << expected << ")\n";
    EXPECT_NEAR(r, expected, 0.02 * expected) << "alpha = " << alpha;
  }
}

TEST(GeneralizedAlphaSpectralRadius, NoDampingAtSmallStep) {
  // At h omega = 1e-2 every variant is close to energy-conserving: |eigenvalue| ~ 1.
  for (double rho : {0.0, 0.5, 0.9}) EXPECT_NEAR(spectral_radius(AlphaCoefficients::from_rho_inf(rho), 1e-2), 1.0, 1e-3);
}

// ---- conditioning of the Newton matrix ----

// Planar pendulum in Cartesian coordinates (mass 2, length 1.5).
class Pendulum {
 public:
  static constexpr int kCoords = 2, kHolonomic = 1, kNonholonomic = 0;
  static constexpr bool kHasEnergy = false;
  std::string formulation_name() const { return "mechanical"; }
  std::vector<ConstraintInfo> constraints() const { return {{"length", "holonomic", "x^2 + y^2 - L^2"}}; }
  void initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
    q << 1.5 * std::sin(0.7), -1.5 * std::cos(0.7);
    v << 0.3 * std::cos(0.7), 0.3 * std::sin(0.7);
  }
  void to_canonical(double, const Vec<double, 2>& q, const Vec<double, 2>& v, double* c) const {
    c[0] = q(0), c[1] = q(1), c[2] = v(0), c[3] = v(1);
  }
  template <class S>
  void mass(const S&, const Vec<S, 2>&, Eigen::Matrix<S, 2, 2>& M) const {
    M = 2.0 * Eigen::Matrix<S, 2, 2>::Identity();
  }
  template <class S>
  void forces(const S&, const Vec<S, 2>&, const Vec<S, 2>& v, Vec<S, 2>& Q) const {
    Q(0) = -0.1 * v(0);
    Q(1) = -2.0 * 9.81 - 0.1 * v(1);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 2>& q, Vec<S, 1>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - 2.25;
  }
};

template <bool kIndex2>
void expect_scaled_condition_bounded() {
  GeneralizedAlphaFormulation<Pendulum, kIndex2> scheme(Pendulum{}, "test", AlphaSettings{});
  using F = decltype(scheme);
  Vec<double, F::kDim> y;
  scheme.initial_state(y.data());
  std::vector<double> hs, scaled, plain;
  for (double h = 1e-2; h >= 0.99e-6; h /= 10) {
    auto cond = [](const typename F::MatN& S) {
      Eigen::JacobiSVD<typename F::MatN> svd(S);
      return svd.singularValues()(0) / svd.singularValues()(F::kN - 1);
    };
    hs.push_back(h);
    scaled.push_back(cond(scheme.newton_matrix(0.0, y.data(), h, true)));
    plain.push_back(cond(scheme.newton_matrix(0.0, y.data(), h, false)));
    std::cout << "[ cond     ] " << (kIndex2 ? "index 2" : "index 3") << " h = " << h << ": scaled " << scaled.back()
              << ", unscaled " << plain.back() << "\n";
  }
  const double slope_scaled = log_slope(hs, scaled), slope_plain = log_slope(hs, plain);
  std::cout << "[ cond     ] slopes d log(cond) / d log(h): scaled " << slope_scaled << ", unscaled " << slope_plain
            << "\n";
  // Bounded with the scaling: within a factor 2 over four decades of h.
  EXPECT_LT(*std::max_element(scaled.begin(), scaled.end()), 2 * *std::min_element(scaled.begin(), scaled.end()));
  EXPECT_LT(std::abs(slope_scaled), 0.05);
  // Without it, it grows at least like h^-2: the slopes differ by more than 40x.
  EXPECT_LE(slope_plain, -1.9);
  EXPECT_GT(std::abs(slope_plain), 40 * std::abs(slope_scaled));
}

TEST(GeneralizedAlphaConditioning, ScaledBoundedUnscaledGrowsIndex3) { expect_scaled_condition_bounded<false>(); }
TEST(GeneralizedAlphaConditioning, ScaledBoundedUnscaledGrowsIndex2) { expect_scaled_condition_bounded<true>(); }

// ---- statistics and starting values ----

TEST(GeneralizedAlphaRun, ReportsNewtonStatisticsAndKeepsConstraints) {
  for (const std::string method : {"generalized-alpha", "hht", "generalized-alpha-i2"}) {
    const RunResult r = run_own("slider-crank", method, 1e-3, 1.0);
    ASSERT_EQ(r.status, "ok") << r.reason;
    std::map<std::string, std::string> extra(r.extra.begin(), r.extra.end());
    ASSERT_TRUE(extra.count("newton_iters")) << method;
    ASSERT_TRUE(extra.count("newton_conv_fails")) << method;
    // At least one iteration per step (1000 steps), and none failed.
    EXPECT_GE(std::stol(extra["newton_iters"]), 1000) << method;
    EXPECT_EQ(extra["newton_conv_fails"], "0") << method;
    EXPECT_EQ(r.steps, 1000);
    // Position constraints to the Newton tolerance; index 2 also the velocity rows.
    EXPECT_LT(r.max_residual, 1e-10) << method;
  }
}

// ---- bad input through the CLI ----

struct CliOutcome {
  int code;
  std::string err;
};

CliOutcome run_cli(const std::vector<std::string>& args, const std::filesystem::path& scratch) {
  std::string cmd = testing::quote(CSTAB_BINARY);
  for (const auto& a : args) {
    cmd += ' ';
    cmd += testing::quote(a);
  }
  const auto err = scratch / "stderr.txt";
  cmd += " >/dev/null 2>";
  cmd += testing::quote(err.string());
  const int status = std::system(cmd.c_str());
  return {testing::exit_code(status), testing::slurp(err)};
}

struct BadCase {
  std::string method, integrator, param, named;
};

TEST(GeneralizedAlphaCli, BadParametersExitTwoWithOneLineAndNoOutput) {
  const std::vector<BadCase> cases = {
      {"generalized-alpha", "own", "rho_inf=1.5", "rho_inf"},
      {"generalized-alpha-i2", "own", "rho_inf=-0.1", "rho_inf"},
      {"hht", "own", "alpha=-0.5", "alpha"},
      {"hht", "own", "alpha=0.1", "alpha"},
      {"generalized-alpha", "own", "newton_iterations=0", "newton_iterations"},
      {"generalized-alpha", "own", "newton_iterations=2.5", "newton_iterations"},
      {"generalized-alpha", "own", "newton_tol=0", "newton_tol"},
      {"ali3p", "own", "alpha=0", "alpha"},
      {"ali3p", "own", "alpha=-1e9", "alpha"},
      {"ali3p", "own", "iterations=0", "iterations"},
      {"ali3p", "own", "tol=nan", "tol"},
      {"penalty", "rk4", "alpha=0", "alpha"},
      {"penalty", "rk4", "omega=-10", "omega"},
      {"penalty", "rk4", "xi=nan", "xi"},
      {"penalty", "own", "", "--integrator"},
      {"generalized-alpha", "rk4", "rho_inf=0.5", "--integrator"},  // wrong pairing
      {"baumgarte", "own", "", "--integrator"},
  };
  for (const auto& c : cases) {
    testing::Scratch s("cstab_genalpha_cli");
    const auto out = s.dir() / "out";
    std::vector<std::string> args = {"run", "--problem", "slider-crank", "--method", c.method, "--integrator",
                                     c.integrator, "--step", "1e-3", "--t-end", "0.1", "--out", out.string()};
    if (!c.param.empty()) {
      args.push_back("--param");
      args.push_back(c.param);
    }
    const CliOutcome o = run_cli(args, s.dir());
    EXPECT_EQ(o.code, 2) << c.method << " " << c.param << ": " << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    EXPECT_NE(o.err.find(c.named), std::string::npos) << o.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.method << " " << c.param;
  }
  // The range is named in the message.
  testing::Scratch s("cstab_genalpha_cli");
  const CliOutcome o = run_cli({"run", "--problem", "slider-crank", "--method", "generalized-alpha", "--integrator",
                                "own", "--step", "1e-3", "--t-end", "0.1", "--param", "rho_inf=1.5", "--out",
                                (s.dir() / "out").string()},
                               s.dir());
  EXPECT_NE(o.err.find("[0, 1]"), std::string::npos) << o.err;
}

}  // namespace
}  // namespace cstab

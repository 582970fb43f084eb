// The generalized-alpha family (methods/generalized_alpha.hpp) on a linear
// test model, against what the papers prove: spectral radius rho_inf at
// h omega -> infinity (Chung & Hulbert 1993; HHT: (1 + alpha)/(1 - alpha)).
// The conditioning of its iteration matrix is in
// test_generalized_alpha_conditioning.cpp (apart, each unit compiles in
// under 1 GB).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "linalg/dense.hpp"
#include "methods/generalized_alpha.hpp"

namespace cstab {
namespace {

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
  // The eigenvalues in linalg (compiled once): an EigenSolver here took this
  // unit over 1 GB and 50 s to compile.
  return linalg::spectral_radius_of(G);
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
    std::cout << "[ spectral ] hht alpha = " << alpha << ": spectral radius at h omega = 1e4: " << r << " (expected "
              << expected << ")\n";
    EXPECT_NEAR(r, expected, 0.02 * expected) << "alpha = " << alpha;
  }
}

TEST(GeneralizedAlphaSpectralRadius, NoDampingAtSmallStep) {
  // At h omega = 1e-2 every variant is close to energy-conserving: |eigenvalue| ~ 1.
  for (double rho : {0.0, 0.5, 0.9})
    EXPECT_NEAR(spectral_radius(AlphaCoefficients::from_rho_inf(rho), 1e-2), 1.0, 1e-3);
}

}  // namespace
}  // namespace cstab

// The flyball governor, problem A05 of the IFToMM multibody benchmark
// library (Gonzalez, Dopico, Lugris and Cuadrado 2006, Multibody System
// Dynamics 16:179-190): the library's stiff problem. The benchmark's own
// specification page (and its reference values) could not be found; the
// data below are those that three independent public implementations of A05
// agree on (docs/problems.md names them and what stays uncertain).
//
// A vertical shaft (1 m tall, 0.01 x 0.01 m section, 0.3 kg) turns freely
// about the z axis from the origin. At its top, z = 1, two rods (1 m,
// 0.01 x 0.01 m, 0.3 kg, each with a 5 kg point mass at its free end) hang
// from revolute joints d = 0.05 m either side of the axis, in one plane
// through it (sigma = +1 and -1). A 3 kg cubic slider (0.1 m side) slides
// along the shaft and turns with it. Where the full governor has a rigid
// coupler from each rod to the slider, A05 has a stiff spring-damper
// (K = 8e5 N/m, C = 4e4 N s/m, rest length l0 = 0.5 m) from the rod's
// midpoint to the slider's side face, d from the axis. Gravity g = 9.81 N/kg
// along -z. At t = 0 the rods point 30 degrees below the horizontal, the
// slider's centre is at z = 0.5 (every spring at its rest length: hinge, rod
// midpoint and slider face make an equilateral triangle of side 0.5), and
// the whole turns rigidly at omega0 = 2 pi rad/s.
//
// Stiffness: each spring-damper is overdamped (damping ratio about 10): a
// slow mode near -K/C = -20 1/s and a fast one near -C/m = -8e3 1/s against
// the mechanism's motion on a time scale of seconds.
//
// Model choices shared by both formulations: the rods are uniform cuboids
// whose inertia about any transverse axis through their centre is
// m (L^2 + w^2) / 12; their spin about their own axis (m w^2 / 6 = 5e-6
// kg m^2, next to 5 kg point masses at 1 m) is left out, so that the
// natural-coordinate mass matrix is constant. The shaft's and slider's
// inertias about z (m (w^2 + w^2) / 12) are kept. Nothing acts about z, so
// the angular momentum about the shaft, Lz, is a first integral; the dampers
// dissipate energy, so there is no energy law.
//
// Two formulations:
//  * FlyballMechanical - natural coordinates q = (R, s, P1, P2) (9): R =
//    (cos theta, sin theta), the shaft's unit radial vector in the rods'
//    plane; s the slider centre's height; P1, P2 the rods' free ends. The
//    hinges are H_i = (0, 0, 1) + sigma_i d R, linear in R, so M is
//    constant. Five holonomic rows: |R|^2 = 1, and per rod |P_i - H_i|^2 =
//    L^2 and (P_i - H_i) . (-R_y, R_x, 0) = 0 (the rod stays in the plane
//    through the shaft). Four degrees of freedom.
//  * FlyballMinimal - theta, s and the rods' angles alpha_i below the
//    horizontal, from rigid-body kinetic energy in cylindrical components
//    (an independent derivation): T = J(alpha) theta'^2 / 2 + m_s s'^2 / 2
//    + A sum alpha_i'^2 / 2, with J = I_shaft + I_slider + sum_i
//    [m_r (d + L/2 cos alpha_i)^2 + I_t cos^2 alpha_i + m_p (d + L cos
//    alpha_i)^2] and A = m_r L^2 / 4 + I_t + m_p L^2. The reference (GSL
//    rk8pd, rtol = atol = 1e-13, problems/common) and `minimal`.
//
// Problem parameters: `stiffness` (K) and `damping` (C).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/params.hpp"
#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"

namespace cstab {

struct FlyballParameters {
  double L = 1.0;           // m, rod length (hinge to point mass)
  double w = 0.01;          // m, rods' and shaft's square section
  double d = 0.05;          // m, hinges' and slider faces' distance from the axis
  double m_rod = 0.3;       // kg, each rod (3000 kg/m^3)
  double m_point = 5.0;     // kg, at each rod's free end
  double m_slider = 3.0;    // kg, 0.1 m cube
  double slider_side = 0.1; // m
  double m_shaft = 0.3;     // kg
  double K = 8e5;           // N/m, spring stiffness
  double C = 4e4;           // N s/m, damping
  double l0 = 0.5;          // m, spring rest length
  double g = 9.81;          // N/kg, along -z
  double alpha0 = 30.0;     // degrees below the horizontal at t = 0
  double s0 = 0.5;          // m, slider centre's height at t = 0
  double omega0 = 2 * 3.14159265358979323846;  // rad/s, the shaft's spin at t = 0

  double I_rod() const { return m_rod * (L * L + w * w) / 12; }                   // transverse, about the centre
  double I_axis() const {                                                         // shaft + slider about z
    return m_shaft * (2 * w * w) / 12 + m_slider * (2 * slider_side * slider_side) / 12;
  }
};

class FlyballMechanical {
 public:
  static constexpr int kCoords = 9, kHolonomic = 5, kNonholonomic = 0;
  static constexpr bool kHasEnergy = false;

  explicit FlyballMechanical(const FlyballParameters& p);

  std::string formulation_name() const { return "mechanical"; }
  static std::vector<ConstraintInfo> constraints();
  void initial_state(Vec<double, 9>& q, Vec<double, 9>& v) const;
  void to_canonical(double, const Vec<double, 9>& q, const Vec<double, 9>& v, double* c) const {
    for (int i = 0; i < 9; ++i) c[i] = q(i), c[9 + i] = v(i);
  }
  template <class S>
  void mass(const S&, const Vec<S, 9>&, Eigen::Matrix<S, 9, 9>& M) const {
    M = M_.template cast<S>();
  }
  // Gravity and the two spring-dampers, from rod i's midpoint (H_i + P_i)/2
  // to the slider face F_i = (0, 0, s) + sigma_i d R: with D_i = midpoint - face
  // = P_i / 2 + (0, 0, 1/2 - s) - sigma_i d R / 2 and l_i = |D_i|, the force
  // f_i = -(K (l_i - l0) + C l_i') D_i / l_i acts on the midpoint and -f_i on
  // the face; Q is (d midpoint/dq - d face/dq)^T f_i.
  template <class S>
  void forces(const S&, const Vec<S, 9>& q, const Vec<S, 9>& v, Vec<S, 9>& Q) const {
    using std::sqrt;
    Q.setZero();
    Q(2) = S(-p_.m_slider * p_.g);
    for (int i = 0; i < 2; ++i) {
      const double sigma = i == 0 ? 1.0 : -1.0;
      const int k = 3 + 3 * i;
      Q(k + 2) += S(-(p_.m_point + p_.m_rod / 2) * p_.g);
      Vec<S, 3> D, Dd;
      for (int j = 0; j < 3; ++j) D(j) = 0.5 * q(k + j), Dd(j) = 0.5 * v(k + j);
      for (int j = 0; j < 2; ++j) D(j) -= 0.5 * sigma * p_.d * q(j), Dd(j) -= 0.5 * sigma * p_.d * v(j);
      D(2) += 0.5 - q(2);
      Dd(2) -= v(2);
      const S l = sqrt(D.dot(D));
      const S tension = p_.K * (l - p_.l0) + p_.C * D.dot(Dd) / l;
      const Vec<S, 3> f = -tension / l * D;
      for (int j = 0; j < 3; ++j) Q(k + j) += 0.5 * f(j);
      for (int j = 0; j < 2; ++j) Q(j) -= 0.5 * sigma * p_.d * f(j);
      Q(2) -= f(2);
    }
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 9>& q, Vec<S, 5>& phi) const {
    phi(0) = q(0) * q(0) + q(1) * q(1) - 1.0;
    for (int i = 0; i < 2; ++i) {
      const double sigma = i == 0 ? 1.0 : -1.0;
      const int k = 3 + 3 * i;
      const S rx = q(k) - sigma * p_.d * q(0), ry = q(k + 1) - sigma * p_.d * q(1), rz = q(k + 2) - 1.0;
      phi(1 + 2 * i) = rx * rx + ry * ry + rz * rz - p_.L * p_.L;
      phi(2 + 2 * i) = -rx * q(1) + ry * q(0);
    }
  }
  // The angular momentum about z: (M v) . (d q / d theta), q turned about z.
  double angular_momentum(const Vec<double, 9>& q, const Vec<double, 9>& v) const;
  const Eigen::Matrix<double, 9, 9>& mass_matrix() const { return M_; }

 private:
  FlyballParameters p_;
  Eigen::Matrix<double, 9, 9> M_;
};

class FlyballMinimal {
 public:
  static constexpr int kStates = 8;  // theta, s, alpha1, alpha2 and their rates

  explicit FlyballMinimal(const FlyballParameters& p) : p_(p), mechanical_(p) {}

  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return FlyballMechanical::constraints(); }
  void initial_state(Vec<double, 8>& y0) const;
  bool rhs(double t, const Vec<double, 8>& y, Vec<double, 8>& dy) const;
  void to_canonical(double t, const Vec<double, 8>& y, double* c) const;
  void residuals(double t, const Vec<double, 8>& y, double* out) const;
  // J(alpha) theta': the angular momentum about z.
  double angular_momentum(const Vec<double, 8>& y) const;

 private:
  double rod_inertia(double cos_alpha) const;

  FlyballParameters p_;
  FlyballMechanical mechanical_;  // its holonomic rows, for residuals()
};

class FlyballGovernor {
 public:
  explicit FlyballGovernor(const FlyballParameters& p = {}) : p_(p), mechanical_(p), minimal_(p) {}

  ProblemInfo info() const;
  std::vector<ParamSpec> problem_params() const;
  FlyballGovernor with_params(const Params& params) const;
  const FlyballMechanical& mechanical() const { return mechanical_; }
  const FlyballMinimal& minimal() const { return minimal_; }
  // "Lz": the angular momentum about the shaft.
  void first_integrals(double t, const double* canonical, double* out) const;
  // Minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;
  const FlyballParameters& parameters() const { return p_; }

 private:
  FlyballParameters p_;
  FlyballMechanical mechanical_;
  FlyballMinimal minimal_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 18);
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(FlyballMechanical);

}  // namespace cstab

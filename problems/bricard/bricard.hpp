// Bricard's mechanism, problem A04 of the IFToMM multibody benchmark library
// (Gonzalez, Dopico, Lugris and Cuadrado 2006, Multibody System Dynamics
// 16:179-190): five rods of length L = 1 m and mass m = 1 kg joined end to
// end, and to the ground, by six revolute joints, under gravity g = 9.81 N/kg
// along -y. Grubler's count gives no degree of freedom; the joint axes make
// it move with one. Its six constraint rows per loop closure are redundant.
//
// Geometry (the benchmark's starting position, as the simEngine3D driver of
// the benchmark lays it out): the joints sit at
//   P0 = (0, 0, 0) and P5 = (0, 0, L) on the ground,
//   P1 = (L, 0, 0), P2 = (L, -L, 0), P3 = (L, -L, L), P4 = (0, -L, L),
// rod k runs from P(k-1) to Pk (k = 1..5), and the ground closes the loop
// from P5 to P0. Every joint's axis is perpendicular to both rods it joins,
// and the two axes of every rod are perpendicular to each other (the
// orthogonal Bricard linkage). Released at rest.
//
// Model: slender rods in natural coordinates q = (P1, P2, P3, P4) (12).
// A rod's kinetic energy is m/6 (|va|^2 + va.vb + |vb|^2), so M is constant
// (2m/3 on each point, m/6 between the points of one rod), and gravity puts
// -m g on each moving point. A rod has no inertia about its own axis, so its
// spin is left out; the benchmark's rods have a 0.1 m square section whose
// inertia (about 1e-3 kg m^2) this model does not carry. With d_k = Pk - P(k-1)
// and d_6 = P0 - P5, the axis of the joint between rods k and k+1 is along
// d_k x d_{k+1}; the rows are
//   |d_k|^2 - L^2 (k = 1..5)                     rod lengths
//   d_1 . e_y,   d_5 . e_x                        the ground joints' axes (e_y at P0, e_x at P5)
//   e_y . (d_1 x d_2),  (d_4 x d_5) . e_x         rods 1 and 5: their two axes stay perpendicular
//   (d_{k-1} x d_k) . (d_k x d_{k+1}), k = 2..4   rods 2..4: likewise
// Twelve rows on twelve coordinates, of rank 11 everywhere on the motion.
//
// Two formulations:
//  * BricardMechanical - the rows above (the DAE every method runs on; those
//    that need full-rank rows refuse it, naming the rank).
//  * BricardMinimal - one degree of freedom, the angle theta of rod 1 about
//    the ground axis e_y at P0: P1 = L (cos theta, 0, -sin theta). P2..P4
//    follow from the ten remaining rows by Gauss-Newton (a QR least-squares
//    step on 10 rows of rank 9, continued from the last solution), their
//    theta-derivatives from the same rows differentiated once and twice, and
//    Lagrange's equation m(theta) theta'' + m'(theta)/2 theta'^2 = -dV/dtheta
//    with m = w^T M w, w = dq/dtheta. It is the reference (GSL rk8pd,
//    rtol = atol = 1e-13, problems/common) and `minimal`.
#pragma once

#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/mechanical.hpp"
#include "methods/model_templates.hpp"
#include "problems/common/reference_cache.hpp"

namespace cstab {

struct BricardParameters {
  double m = 1.0;     // kg, each rod
  double L = 1.0;     // m, each rod
  double g = 9.81;    // N/kg, along -y
};

namespace bricard_detail {
template <class S>
Vec<S, 3> cross(const Vec<S, 3>& a, const Vec<S, 3>& b) {
  Vec<S, 3> c;
  c(0) = a(1) * b(2) - a(2) * b(1);
  c(1) = a(2) * b(0) - a(0) * b(2);
  c(2) = a(0) * b(1) - a(1) * b(0);
  return c;
}

// The twelve rows above at the points P1..P4 = q(0..11).
template <class S, class Q, class Phi>
void rows(double L, const Q& q, Phi& phi) {
  Vec<S, 3> p[6];
  p[0].setZero();
  for (int k = 1; k <= 4; ++k) p[k] = q.template segment<3>(3 * (k - 1));
  p[5] << S(0.0), S(0.0), S(L);
  Vec<S, 3> d[7];
  for (int k = 1; k <= 5; ++k) d[k] = p[k] - p[k - 1];
  d[6] = p[0] - p[5];
  d[0] = d[6];
  for (int k = 1; k <= 5; ++k) phi(k - 1) = d[k].dot(d[k]) - L * L;
  phi(5) = d[1](1);   // d_1 . e_y
  phi(6) = d[5](0);   // d_5 . e_x
  Vec<S, 3> n[6];     // n[k]: axis of the joint between rods k and k+1
  for (int k = 1; k <= 4; ++k) n[k] = cross(d[k], d[k + 1]);
  phi(7) = n[1](1);   // e_y . (d_1 x d_2)
  phi(8) = n[4](0);   // (d_4 x d_5) . e_x
  for (int k = 2; k <= 4; ++k) phi(7 + k) = n[k - 1].dot(n[k]);
}
}  // namespace bricard_detail

class BricardMechanical {
 public:
  static constexpr int kCoords = 12, kHolonomic = 12, kNonholonomic = 0;
  static constexpr bool kHasEnergy = true;

  explicit BricardMechanical(const BricardParameters& p) : p_(p) {}

  std::string formulation_name() const { return "mechanical"; }
  static std::vector<ConstraintInfo> constraints();
  void initial_state(Vec<double, 12>& q, Vec<double, 12>& v) const;
  void to_canonical(double, const Vec<double, 12>& q, const Vec<double, 12>& v, double* c) const {
    for (int i = 0; i < 12; ++i) c[i] = q(i), c[12 + i] = v(i);
  }
  template <class S>
  void mass(const S&, const Vec<S, 12>&, Eigen::Matrix<S, 12, 12>& M) const {
    M.setZero();
    for (int k = 0; k < 4; ++k)
      for (int i = 0; i < 3; ++i) {
        M(3 * k + i, 3 * k + i) = S(2 * p_.m / 3);
        if (k < 3) M(3 * k + i, 3 * k + 3 + i) = M(3 * k + 3 + i, 3 * k + i) = S(p_.m / 6);
      }
  }
  template <class S>
  void forces(const S&, const Vec<S, 12>&, const Vec<S, 12>&, Vec<S, 12>& Q) const {
    for (int i = 0; i < 12; ++i) Q(i) = S(i % 3 == 1 ? -p_.m * p_.g : 0.0);
  }
  template <class S>
  void holonomic(const S&, const Vec<S, 12>& q, Vec<S, 12>& phi) const {
    bricard_detail::rows<S>(p_.L, q, phi);
  }
  template <class S>
  S energy(const S&, const Vec<S, 12>& q, const Vec<S, 12>& v) const {
    Eigen::Matrix<S, 12, 12> M;
    mass(S(0.0), q, M);
    S potential = S(0.0);
    for (int k = 0; k < 4; ++k) potential += p_.m * p_.g * q(3 * k + 1);
    return 0.5 * v.dot(M * v) + potential;
  }

 private:
  BricardParameters p_;
};

class BricardMinimal {
 public:
  static constexpr int kStates = 2;  // theta, theta'

  explicit BricardMinimal(const BricardParameters& p) : p_(p), mech_(p) {}

  std::string formulation_name() const { return "minimal"; }
  std::vector<ConstraintInfo> constraints() const { return BricardMechanical::constraints(); }
  void initial_state(Vec<double, 2>& y0) const { y0.setZero(); }
  bool rhs(double t, const Vec<double, 2>& y, Vec<double, 2>& dy) const;
  void to_canonical(double t, const Vec<double, 2>& y, double* c) const;
  void residuals(double t, const Vec<double, 2>& y, double* out) const;

  // The position analysis at theta: q (12), w = dq/dtheta and dw/dtheta.
  // False if Gauss-Newton does not converge (theta out of the motion's reach).
  bool kinematics(double theta, Vec<double, 12>& q, Vec<double, 12>& w, Vec<double, 12>& dw) const;

 private:
  // P2..P4 at theta into z, with the rows' Jacobians in z (10 x 9) and in
  // theta there (the last Gauss-Newton evaluation).
  bool solve(double theta, Vec<double, 9>& z, Eigen::Matrix<double, 10, 9>& Jz, Vec<double, 10>& Jt) const;
  BricardParameters p_;
  BricardMechanical mech_;
  // The last solution, the start of the next Gauss-Newton (a copy per
  // formulation; the reference cache serializes its calls).
  mutable double last_theta_ = 0;
  mutable Vec<double, 9> last_z_ = (Vec<double, 9>() << 1, -1, 0, 1, -1, 1, 0, -1, 1).finished();
};

class Bricard {
 public:
  explicit Bricard(const BricardParameters& p = {}) : p_(p), mechanical_(p), minimal_(p) {}

  ProblemInfo info() const;
  const BricardMechanical& mechanical() const { return mechanical_; }
  const BricardMinimal& minimal() const { return minimal_; }
  double energy(double t, const double* canonical) const;
  // Minimal-coordinate solution by GSL rk8pd at rtol = atol = 1e-13, cached.
  bool reference(double t, double* canonical) const;
  const BricardParameters& parameters() const { return p_; }

 private:
  BricardParameters p_;
  BricardMechanical mechanical_;
  BricardMinimal minimal_;
  ReferenceCache reference_ = reference_cache_of(minimal_, 24);
};

// Compiled once (cstab_model in CMakeLists.txt); the method units reuse it.
CSTAB_EXTERN_MODEL_TEMPLATES(BricardMechanical);

}  // namespace cstab

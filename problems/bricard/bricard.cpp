#include "problems/bricard/bricard.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "core/autodiff.hpp"

namespace cstab {

std::vector<ConstraintInfo> BricardMechanical::constraints() {
  std::vector<ConstraintInfo> rows;
  for (int k = 1; k <= 5; ++k)
    rows.push_back({"rod" + std::to_string(k), "holonomic", "|P" + std::to_string(k) + " - P" + std::to_string(k - 1) +
                                                                "|^2 - L^2: rod " + std::to_string(k) + " keeps its length"});
  rows.push_back({"axis0", "holonomic", "d_1 . e_y: rod 1 stays perpendicular to the ground joint's axis at P0"});
  rows.push_back({"axis5", "holonomic", "d_5 . e_x: rod 5 stays perpendicular to the ground joint's axis at P5"});
  rows.push_back({"twist1", "holonomic", "e_y . (d_1 x d_2): rod 1's two joint axes stay perpendicular"});
  rows.push_back({"twist5", "holonomic", "(d_4 x d_5) . e_x: rod 5's two joint axes stay perpendicular"});
  for (int k = 2; k <= 4; ++k)
    rows.push_back({"twist" + std::to_string(k), "holonomic",
                    "(d_" + std::to_string(k - 1) + " x d_" + std::to_string(k) + ") . (d_" + std::to_string(k) +
                        " x d_" + std::to_string(k + 1) + "): rod " + std::to_string(k) +
                        "'s two joint axes stay perpendicular"});
  return rows;
}

void BricardMechanical::initial_state(Vec<double, 12>& q, Vec<double, 12>& v) const {
  const double L = p_.L;
  q << L, 0, 0, L, -L, 0, L, -L, L, 0, -L, L;
  v.setZero();
}

// ---------------------------------------------------------------------------
// The minimal formulation. F(z, theta): the ten rows other than rod1 and
// axis0 (which P1(theta) satisfies by construction) at q = (P1(theta), z).

namespace {

constexpr int kRows = 10;
constexpr int kSkipped[2] = {0, 5};  // rod1, axis0

template <class S>
Vec<S, 3> point1(double L, const S& theta) {
  using std::cos;
  using std::sin;
  Vec<S, 3> p;
  p << L * cos(theta), S(0.0), -L * sin(theta);
  return p;
}

template <class S>
void reduced_rows(double L, const S& theta, const Vec<S, 9>& z, Vec<S, kRows>& F) {
  Vec<S, 12> q;
  q.template head<3>() = point1(L, theta);
  q.template tail<9>() = z;
  Vec<S, 12> phi;
  bricard_detail::rows<S>(L, q, phi);
  for (int i = 0, j = 0; i < 12; ++i)
    if (i != kSkipped[0] && i != kSkipped[1]) F(j++) = phi(i);
}

using D10 = ad::Dual<10>;  // z (9) and theta

// F and its Jacobian in (z, theta).
void rows_and_jacobian(double L, double theta, const Vec<double, 9>& z, Vec<double, kRows>& F,
                       Eigen::Matrix<double, kRows, 9>& Jz, Vec<double, kRows>& Jt) {
  Vec<D10, 9> zd;
  for (int i = 0; i < 9; ++i) zd(i) = D10(z(i), 10, i);
  const D10 td(theta, 10, 9);
  Vec<D10, kRows> Fd;
  reduced_rows<D10>(L, td, zd, Fd);
  for (int r = 0; r < kRows; ++r) {
    F(r) = Fd(r).value();
    Jz.row(r) = Fd(r).derivatives().head<9>().transpose();
    Jt(r) = Fd(r).derivatives()(9);
  }
}

}  // namespace

bool BricardMinimal::solve(double theta, Vec<double, 9>& z, Eigen::Matrix<double, kRows, 9>& Jz,
                           Vec<double, kRows>& Jt) const {
  Vec<double, kRows> F;
  // Continue from the last solution in steps of at most 0.02 rad.
  const int pieces = std::max(1, static_cast<int>(std::ceil(std::abs(theta - last_theta_) / 0.02)));
  z = last_z_;
  for (int k = 1; k <= pieces; ++k) {
    const double th = k == pieces ? theta : last_theta_ + (theta - last_theta_) * k / pieces;
    bool converged = false;
    for (int it = 0; it < 50 && !converged; ++it) {
      rows_and_jacobian(p_.L, th, z, F, Jz, Jt);
      const Vec<double, 9> dz = Jz.colPivHouseholderQr().solve(F);
      z -= dz;
      converged = dz.lpNorm<Eigen::Infinity>() < 1e-14 * (1 + z.lpNorm<Eigen::Infinity>());
    }
    rows_and_jacobian(p_.L, th, z, F, Jz, Jt);
    if (!converged && F.lpNorm<Eigen::Infinity>() > 1e-13) return false;
  }
  last_theta_ = theta;
  last_z_ = z;
  return true;
}

bool BricardMinimal::kinematics(double theta, Vec<double, 12>& q, Vec<double, 12>& w, Vec<double, 12>& dw) const {
  Vec<double, 9> z;
  Vec<double, kRows> Jt;
  Eigen::Matrix<double, kRows, 9> Jz;
  if (!solve(theta, z, Jz, Jt)) return false;
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, kRows, 9>> qr(Jz);
  if (qr.rank() < 9) return false;  // theta is no coordinate of the motion here
  // Once: Jz z' = -Jt. Twice: Jz z'' = -d2/ds2 F(z + s z', theta + s) at s = 0.
  const Vec<double, 9> zt = qr.solve(-Jt);
  // Two copies of one direction, s1 (inner) and s2 (outer): the mixed
  // derivative of F(z + (s1 + s2) z', theta + s1 + s2) is the second one.
  using D1 = ad::Dual<1>;
  using D2 = ad::Dual<1, D1>;
  auto seeded = [](double x, double dx) {
    return D2(D1(x, Eigen::Matrix<double, 1, 1>(dx)), Eigen::Matrix<D1, 1, 1>(D1(dx, Eigen::Matrix<double, 1, 1>(0.0))));
  };
  Vec<D2, 9> zs;
  for (int i = 0; i < 9; ++i) zs(i) = seeded(z(i), zt(i));
  const D2 ts = seeded(theta, 1.0);
  Vec<D2, kRows> Fs;
  reduced_rows<D2>(p_.L, ts, zs, Fs);
  Vec<double, kRows> curvature;
  for (int r = 0; r < kRows; ++r) curvature(r) = Fs(r).derivatives()(0).derivatives()(0);
  const Vec<double, 9> ztt = qr.solve(-curvature);
  const double L = p_.L, c = std::cos(theta), s = std::sin(theta);
  q << L * c, 0, -L * s, z;
  w << -L * s, 0, -L * c, zt;
  dw << -L * c, 0, L * s, ztt;
  return true;
}

bool BricardMinimal::rhs(double, const Vec<double, 2>& y, Vec<double, 2>& dy) const {
  Vec<double, 12> q, w, dw;
  if (!kinematics(y(0), q, w, dw)) return false;
  Eigen::Matrix<double, 12, 12> M;
  mech_.mass(0.0, q, M);
  Vec<double, 12> Q;
  mech_.forces(0.0, q, q, Q);
  const double m = w.dot(M * w);
  dy(0) = y(1);
  dy(1) = (w.dot(Q) - w.dot(M * dw) * y(1) * y(1)) / m;
  return true;
}

void BricardMinimal::to_canonical(double, const Vec<double, 2>& y, double* c) const {
  Vec<double, 12> q, w, dw;
  if (!kinematics(y(0), q, w, dw)) {
    std::fill(c, c + 24, std::nan(""));
    return;
  }
  for (int i = 0; i < 12; ++i) c[i] = q(i), c[12 + i] = w(i) * y(1);
}

void BricardMinimal::residuals(double t, const Vec<double, 2>& y, double* out) const {
  double c[24];
  to_canonical(t, y, c);
  Vec<double, 12> phi;
  bricard_detail::rows<double>(p_.L, vmap<12>(c).eval(), phi);
  for (int i = 0; i < 12; ++i) out[i] = phi(i);
}

// ---------------------------------------------------------------------------

ProblemInfo Bricard::info() const {
  ProblemInfo info;
  info.name = "bricard";
  info.description =
      "IFToMM benchmark A04: Bricard's mechanism, five 1 m, 1 kg rods on six revolute joints under gravity, "
      "released at rest; 12 redundant rows of rank 11 (one degree of freedom)";
  for (int k = 1; k <= 4; ++k)
    for (const char* axis : {"x", "y", "z"}) info.coordinates.push_back(std::string(axis) + std::to_string(k));
  for (int k = 1; k <= 4; ++k)
    for (const char* axis : {"x", "y", "z"}) info.coordinates.push_back(std::string(axis) + std::to_string(k) + "dot");
  info.formulations = {
      {"mechanical", "natural coordinates q = (P1, P2, P3, P4), constant M, 12 rows of rank 11",
       BricardMechanical::constraints()},
      {"minimal", "the angle theta of rod 1 about the ground axis at P0; P2..P4 by Gauss-Newton on the rows",
       BricardMechanical::constraints()},
  };
  info.has_energy = true;
  info.default_t_end = 10;
  info.reference_time = 10;
  info.reference_description =
      "minimal-coordinate ODE (rod 1's angle, the other points by Gauss-Newton), GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

double Bricard::energy(double, const double* c) const {
  Vec<double, 12> q = vmap<12>(c), v = vmap<12>(c + 12);
  return mechanical_.energy(0.0, q, v);
}

bool Bricard::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

}  // namespace cstab

#include "problems/flyball_governor/flyball_governor.hpp"

#include <algorithm>
#include <cmath>

#include "core/format.hpp"

namespace cstab {

namespace {
constexpr double kPi = 3.14159265358979323846;
double sign_of(int rod) { return rod == 0 ? 1.0 : -1.0; }
}  // namespace

// The kinetic energy in natural coordinates, term by term (H_i' = sigma_i d R'):
//   shaft and slider about z:  I_axis |R'|^2 / 2          (|R| = 1: |R'| = theta')
//   slider along z:            m_s s'^2 / 2
//   rod i:                     m_r |H_i' + P_i'|^2 / 8 + I_t |P_i' - H_i'|^2 / (2 L^2)
//                              (its centre's speed, and |u'| = |omega_perp| for u = (P - H) / L)
//   point mass i:              m_p |P_i'|^2 / 2
FlyballMechanical::FlyballMechanical(const FlyballParameters& p) : p_(p) {
  const double L2 = p.L * p.L, It = p.I_rod();
  const double hh = p.m_rod / 4 + It / L2;             // |H'|^2 and |P'|^2 coefficient (x 2) of a rod
  const double hp = p.m_rod / 4 - It / L2;             // H' . P' coefficient of a rod
  M_.setZero();
  M_(0, 0) = M_(1, 1) = p.I_axis() + 2 * p.d * p.d * hh;
  M_(2, 2) = p.m_slider;
  for (int i = 0; i < 2; ++i) {
    const int k = 3 + 3 * i;
    for (int j = 0; j < 3; ++j) M_(k + j, k + j) = hh + p.m_point;
    for (int j = 0; j < 2; ++j) M_(k + j, j) = M_(j, k + j) = sign_of(i) * p.d * hp;
  }
}

std::vector<ConstraintInfo> FlyballMechanical::constraints() {
  return {{"unit", "holonomic", "Rx^2 + Ry^2 - 1: R is the shaft's unit radial vector"},
          {"rod1", "holonomic", "|P1 - H1|^2 - L^2: rod 1 keeps its length"},
          {"plane1", "holonomic", "(P1 - H1) . (-Ry, Rx, 0): rod 1 stays in the plane through the shaft"},
          {"rod2", "holonomic", "|P2 - H2|^2 - L^2: rod 2 keeps its length"},
          {"plane2", "holonomic", "(P2 - H2) . (-Ry, Rx, 0): rod 2 stays in the plane through the shaft"}};
}

void FlyballMechanical::initial_state(Vec<double, 9>& q, Vec<double, 9>& v) const {
  const double a = p_.alpha0 * kPi / 180, reach = p_.d + p_.L * std::cos(a), z = 1 - p_.L * std::sin(a);
  q << 1, 0, p_.s0, reach, 0, z, -reach, 0, z;
  // Rigid rotation about z at omega0: v = omega0 (q turned by 90 degrees).
  v.setZero();
  v(1) = p_.omega0;
  v(4) = p_.omega0 * reach;
  v(7) = -p_.omega0 * reach;
}

double FlyballMechanical::angular_momentum(const Vec<double, 9>& q, const Vec<double, 9>& v) const {
  Vec<double, 9> turned;
  turned << -q(1), q(0), 0, -q(4), q(3), 0, -q(7), q(6), 0;
  return (M_ * v).dot(turned);
}

// ---------------------------------------------------------------------------
// The minimal formulation: y = (theta, s, alpha1, alpha2, and their rates).
// Rod i's centre and free end sit at radius sigma_i (d + a cos alpha_i)
// (a = L/2) and sigma_i (d + L cos alpha_i) in the turning plane, heights
// 1 - a sin alpha_i and 1 - L sin alpha_i; the rod turns at theta' e_z +
// alpha_i' n_i (n_i horizontal, normal to the plane), so its angular velocity
// across its axis has |omega_perp|^2 = alpha_i'^2 + theta'^2 cos^2 alpha_i.
// Lagrange's equations, with the spring-dampers' generalized forces
// -T_i dl_i/dq (tension T_i = K (l_i - l0) + C l_i', length
// l_i^2 = a^2 cos^2 alpha_i + h_i^2, h_i = 1 - s - a sin alpha_i):
//   J theta'' + sum_i j'(alpha_i) alpha_i' theta' = 0
//   m_s s'' = -m_s g - sum_i T_i dl_i/ds,                  dl/ds = -h / l
//   A alpha_i'' = j'(alpha_i) theta'^2 / 2 + (m_r a + m_p L) g cos alpha_i
//                 - T_i dl_i/dalpha_i,                      dl/dalpha = -a cos alpha (1 - s) / l

// One rod's and its point mass's inertia about z at cos alpha = c.
double FlyballMinimal::rod_inertia(double c) const {
  const double a = p_.L / 2, L = p_.L, d = p_.d;
  return p_.m_rod * (d + a * c) * (d + a * c) + p_.I_rod() * c * c + p_.m_point * (d + L * c) * (d + L * c);
}

void FlyballMinimal::initial_state(Vec<double, 8>& y0) const {
  const double a = p_.alpha0 * kPi / 180;
  y0 << 0, p_.s0, a, a, p_.omega0, 0, 0, 0;
}

bool FlyballMinimal::rhs(double, const Vec<double, 8>& y, Vec<double, 8>& dy) const {
  const double a = p_.L / 2, It = p_.I_rod(), L = p_.L, d = p_.d;
  const double A = p_.m_rod * a * a + It + p_.m_point * L * L;
  const double s = y(1), sdot = y(5), thdot = y(4);
  double J = p_.I_axis(), Jdot = 0;
  double jp[2], force_s = -p_.m_slider * p_.g, acc_alpha[2];
  for (int i = 0; i < 2; ++i) {
    const double al = y(2 + i), ald = y(6 + i), c = std::cos(al), sn = std::sin(al);
    J += rod_inertia(c);
    jp[i] = -2 * sn * (p_.m_rod * a * (d + a * c) + It * c + p_.m_point * L * (d + L * c));
    Jdot += jp[i] * ald;
    const double h = 1 - s - a * sn, l = std::sqrt(a * a * c * c + h * h);
    const double dl_dalpha = -a * c * (1 - s) / l, dl_ds = -h / l;
    const double ldot = dl_dalpha * ald + dl_ds * sdot;
    const double tension = p_.K * (l - p_.l0) + p_.C * ldot;  // pulls along -dl/dq
    force_s += -tension * dl_ds;
    acc_alpha[i] = (jp[i] * thdot * thdot / 2 + (p_.m_rod * a + p_.m_point * L) * p_.g * c - tension * dl_dalpha) / A;
  }
  dy.head<4>() = y.tail<4>();
  dy(4) = -Jdot * thdot / J;
  dy(5) = force_s / p_.m_slider;
  dy(6) = acc_alpha[0];
  dy(7) = acc_alpha[1];
  return true;
}

void FlyballMinimal::to_canonical(double, const Vec<double, 8>& y, double* c) const {
  const double th = y(0), thd = y(4), ct = std::cos(th), st = std::sin(th);
  c[0] = ct, c[1] = st, c[2] = y(1);
  c[9] = -st * thd, c[10] = ct * thd, c[11] = y(5);
  for (int i = 0; i < 2; ++i) {
    const double sigma = sign_of(i), al = y(2 + i), ald = y(6 + i);
    const double rho = sigma * (p_.d + p_.L * std::cos(al)), rhod = -sigma * p_.L * std::sin(al) * ald;
    const int k = 3 + 3 * i;
    c[k] = rho * ct, c[k + 1] = rho * st, c[k + 2] = 1 - p_.L * std::sin(al);
    c[9 + k] = rhod * ct - rho * st * thd;
    c[9 + k + 1] = rhod * st + rho * ct * thd;
    c[9 + k + 2] = -p_.L * std::cos(al) * ald;
  }
}

void FlyballMinimal::residuals(double t, const Vec<double, 8>& y, double* out) const {
  double c[18];
  to_canonical(t, y, c);
  Vec<double, 5> phi;
  mechanical_.holonomic(0.0, vmap<9>(c).eval(), phi);
  for (int i = 0; i < 5; ++i) out[i] = phi(i);
}

double FlyballMinimal::angular_momentum(const Vec<double, 8>& y) const {
  return (p_.I_axis() + rod_inertia(std::cos(y(2))) + rod_inertia(std::cos(y(3)))) * y(4);
}

// ---------------------------------------------------------------------------

ProblemInfo FlyballGovernor::info() const {
  ProblemInfo info;
  info.name = "flyball-governor";
  info.description =
      "IFToMM benchmark A05: a flyball governor turning freely at 2 pi rad/s, its rod-to-slider couplers "
      "replaced by stiff spring-dampers (K = " + format_short(p_.K) + " N/m, C = " + format_short(p_.C) +
      " N s/m): the stiff problem";
  info.coordinates = {"Rx", "Ry", "s", "x1", "y1", "z1", "x2", "y2", "z2"};
  for (int i = 0; i < 9; ++i) info.coordinates.push_back(info.coordinates[i] + "dot");
  info.formulations = {
      {"mechanical", "natural coordinates q = (R, s, P1, P2): the shaft's radial unit vector, the slider's height "
                     "and the rods' free ends; constant M, five holonomic rows",
       FlyballMechanical::constraints()},
      {"minimal", "the shaft angle, the slider's height and the rods' angles below the horizontal (Lagrange's "
                  "equations from rigid-body kinetic energy)",
       FlyballMechanical::constraints()},
  };
  info.has_energy = false;
  info.first_integrals = {"Lz"};
  info.default_t_end = 10;
  info.reference_time = 10;
  // The fast mode: the linearization of the minimal model at the start has
  // eigenvalues -8117, -1450, -20.3, -20.1 and +-7.35i 1/s (K = 8e5, C = 4e4),
  // -8117 being the rods' spring-dampers in phase with an effective mass of
  // about 4.9 kg: rate max(C, sqrt(K m)) / m. Twice its time constant keeps
  // h times the rate under RK4's real stability limit 2.785; the conformance
  // suite runs fixed-step methods at this step or finer, and
  // tests/regression/test_flyball.cpp shows what a coarser step does.
  const double m_fast = 4.9, rate = std::max(p_.C, std::sqrt(p_.K * m_fast)) / m_fast;
  info.resolution_step = rate > 0 ? 2 / rate : 0;
  info.reference_description =
      "minimal-coordinate ODE (shaft angle, slider height, rod angles), GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

std::vector<ParamSpec> FlyballGovernor::problem_params() const {
  return {ranged_param("stiffness", p_.K, 0, 1e9, "spring stiffness K of the two rod-to-slider spring-dampers, N/m"),
          ranged_param("damping", p_.C, 0, 1e8, "damping C of the two rod-to-slider spring-dampers, N s/m")};
}

FlyballGovernor FlyballGovernor::with_params(const Params& params) const {
  FlyballParameters p = p_;
  p.K = params.get("stiffness");
  p.C = params.get("damping");
  return FlyballGovernor(p);
}

void FlyballGovernor::first_integrals(double, const double* c, double* out) const {
  out[0] = mechanical_.angular_momentum(vmap<9>(c).eval(), vmap<9>(c + 9).eval());
}

bool FlyballGovernor::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

}  // namespace cstab

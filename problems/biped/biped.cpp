#include "problems/biped/biped.hpp"

#include <array>
#include <complex>
#include <stdexcept>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "core/autodiff.hpp"

namespace cstab {

// ---------------------------------------------------------------------------
// Kinematic chains (see the header for the geometry).
// ---------------------------------------------------------------------------

BipedMechanical::Chain BipedMechanical::knee(int leg) const {
  return {{Link{qTH, -p_.lc, 0}, Link{leg == 0 ? qT1 : qT4, -p_.l1, 0}}, 2};
}

BipedMechanical::Chain BipedMechanical::ankle(int leg) const {
  Chain c = knee(leg);
  c.links[c.n++] = Link{leg == 0 ? qT2 : qT5, -p_.l2, 0};
  return c;
}

BipedMechanical::Chain BipedMechanical::heel(int leg) const {
  Chain c = ankle(leg);
  c.links[c.n++] = Link{leg == 0 ? qT3 : qT6, -p_.b, -p_.h};
  return c;
}

BipedMechanical::Chain BipedMechanical::toe(int leg) const {
  Chain c = ankle(leg);
  c.links[c.n++] = Link{leg == 0 ? qT3 : qT6, p_.a, -p_.h};
  return c;
}

BipedMechanical::Chain BipedMechanical::body_com(int k) const {
  switch (k) {
    case 0: return {{}, 0};  // HAT: (x, y) is its centre of mass
    case 1:
    case 4: {
      const int leg = k == 1 ? 0 : 1;
      return {{Link{qTH, -p_.lc, 0}, Link{leg == 0 ? qT1 : qT4, -p_.thigh_com * p_.l1, 0}}, 2};
    }
    case 2:
    case 5: {
      const int leg = k == 2 ? 0 : 1;
      Chain c = knee(leg);
      c.links[c.n++] = Link{leg == 0 ? qT2 : qT5, -p_.shank_com * p_.l2, 0};
      return c;
    }
    case 3:
    case 6: {
      const int leg = k == 3 ? 0 : 1;
      Chain c = ankle(leg);
      c.links[c.n++] = Link{leg == 0 ? qT3 : qT6, 0.5 * p_.a, -0.5 * p_.h};
      return c;
    }
    default: throw std::out_of_range("biped body index");
  }
}

namespace {
// The segment body k is (bodies 1-3: leg 1, 4-6: leg 2): 0 the HAT, 1 a
// thigh, 2 a shank, 3 a foot.
int segment_of(int k) { return k == 0 ? 0 : (k - 1) % 3 + 1; }
}  // namespace

double BipedMechanical::body_mass(int k) const {
  return std::array<double, 4>{p_.m_hat, p_.m_thigh, p_.m_shank, p_.m_foot}[segment_of(k)];
}

double BipedMechanical::body_inertia(int k) const {
  return std::array<double, 4>{p_.i_hat, p_.i_thigh, p_.i_shank, p_.i_foot}[segment_of(k)];
}

std::vector<ConstraintInfo> BipedMechanical::constraints() const {
  return {
      {"heel1", "holonomic", "Phi_1: height of the forward (leg 1) heel = 0"},
      {"toe2", "holonomic", "Phi_2: height of the backward (leg 2) toe = 0"},
      {"knee1", "holonomic", "Phi_3: theta2 - theta1 + pi/10 (1 - cos(omega t)) = 0"},
      {"knee2", "holonomic", "Phi_4: theta5 - theta4 + pi/10 (1 - cos(omega t)) = 0"},
      {"trunk", "holonomic", "Phi_5: theta - 4pi/9 + pi/18 (1 - cos(omega t)) = 0"},
      {"foot1", "holonomic", "Phi_6: theta3 - pi/18 (1 + cos(omega t)) = 0"},
      {"foot2", "holonomic", "Phi_7: theta6 + pi/18 (1 - cos(omega t)) = 0"},
      {"heel1_fixed", "non-holonomic (integrable)", "Psi_1: horizontal velocity of the forward heel = 0"},
      {"toe2_fixed", "non-holonomic (integrable)", "Psi_2: horizontal velocity of the backward toe = 0"},
  };
}

void BipedMechanical::initial_state(Vec<double, 9>& q, Vec<double, 9>& v) const {
  for (int i = 0; i < 9; ++i) q(i) = p_.q0[i];
  v.setZero();
}

// ---------------------------------------------------------------------------
// Exact kinematic solution.
// ---------------------------------------------------------------------------

namespace {

// The 9 equations [Phi(t, q); x_heel1(q) - X1; x_toe2(q) - X2].
template <class S>
Vec<S, 9> kinematic_equations(const BipedMechanical& m, const S& t, const Vec<S, 9>& q, const Vec<double, 2>& X) {
  Vec<S, 7> phi;
  m.holonomic(t, q, phi);
  const Vec<S, 2> xc = m.contact_abscissae(q);
  Vec<S, 9> f;
  f.template head<7>() = phi;
  f(7) = xc(0) - X(0);
  f(8) = xc(1) - X(1);
  return f;
}

// Value, Jacobian d/dq and d/dt of the 9 equations.
void kinematic_jacobian(const BipedMechanical& m, double t, const Vec<double, 9>& q, const Vec<double, 2>& X,
                        Vec<double, 9>& f, Eigen::Matrix<double, 9, 9>& J, Vec<double, 9>& ft) {
  using D = ad::Dual<10>;
  Vec<D, 9> qd;
  for (int i = 0; i < 9; ++i) qd(i) = D(q(i), 10, i);
  const D td(t, 10, 9);
  const Vec<D, 9> fd = kinematic_equations(m, td, qd, X);
  for (int i = 0; i < 9; ++i) {
    f(i) = fd(i).value();
    J.row(i) = fd(i).derivatives().head<9>().transpose();
    ft(i) = fd(i).derivatives()(9);
  }
}

}  // namespace

Biped::Biped() : Biped(BipedParameters{}) {}

namespace {

// Holonomic residual and Jacobian at t = 0.
void phi_and_jacobian(const BipedMechanical& m, const Vec<double, 9>& q, Vec<double, 7>& phi,
                      Eigen::Matrix<double, 7, 9>& J) {
  using D = ad::Dual<9>;
  Vec<D, 9> qd;
  for (int i = 0; i < 9; ++i) qd(i) = D(q(i), 9, i);
  Vec<D, 7> phid;
  m.holonomic(D(0.0), qd, phid);
  for (int i = 0; i < 7; ++i) {
    phi(i) = phid(i).value();
    J.row(i) = phid(i).derivatives().transpose();
  }
}

// dq/dtau = -M(q)^-1 J^T (J M(q)^-1 J^T)^-1 Phi(0, q): along it Phi = Phi_0 e^-tau.
int correction_flow(double, const double y[], double dydt[], void* model) {
  const auto& m = *static_cast<const BipedMechanical*>(model);
  const Vec<double, 9> q = Eigen::Map<const Vec<double, 9>>(y);
  Vec<double, 7> phi;
  Eigen::Matrix<double, 7, 9> J;
  phi_and_jacobian(m, q, phi, J);
  Eigen::Matrix<double, 9, 9> M;
  m.mass(0.0, q, M);
  const Eigen::Matrix<double, 9, 7> MiJt = M.llt().solve(J.transpose());
  const Eigen::Matrix<double, 7, 7> S = J * MiJt;
  vmap<9>(dydt) = -MiJt * S.ldlt().solve(phi);
  return GSL_SUCCESS;
}

}  // namespace

Biped::Biped(const BipedParameters& p) : params_(p), mechanical_(p) {
  Vec<double, 9> q0, v0;
  mechanical_.initial_state(q0, v0);

  // (1) Kinetic-metric projection of q0 onto Phi(0, q) = 0 with W = M(q0):
  // iterate q <- q0 - W^-1 J^T (J W^-1 J^T)^-1 (Phi(q) - J (q - q0)), J = J(q).
  // A fixed point satisfies Phi(q) = 0 and W (q - q0) = -J^T mu: the KKT
  // conditions of min (q - q0)^T W (q - q0) subject to Phi(0, q) = 0.
  Eigen::Matrix<double, 9, 9> W;
  mechanical_.mass(0.0, q0, W);
  const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(W);
  Vec<double, 9> q = q0;
  for (int it = 0; it < 100; ++it) {
    Vec<double, 7> phi;
    Eigen::Matrix<double, 7, 9> J;
    phi_and_jacobian(mechanical_, q, phi, J);
    const Eigen::Matrix<double, 9, 7> WiJt = llt.solve(J.transpose());
    const Eigen::Matrix<double, 7, 7> S = J * WiJt;
    const Vec<double, 9> next = q0 - WiJt * S.ldlt().solve(phi - J * (q - q0));
    const bool done = (next - q).lpNorm<Eigen::Infinity>() < 1e-15;
    q = next;
    if (done) break;
  }
  q_proj_ = q;

  // (2) End point of the correction flow from q0 (GSL rk8pd, tight tolerance,
  // to tau = 40 where Phi = Phi_0 e^-40), then Gauss-Newton steps along the
  // same directions to remove the last e^-40 and the integration error.
  std::array<double, 9> y;
  for (int i = 0; i < 9; ++i) y[i] = q0(i);
  gsl_odeiv2_system sys{correction_flow, nullptr, 9, const_cast<BipedMechanical*>(&mechanical_)};
  gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-3, 1e-14, 1e-14);
  double tau = 0;
  const int status = gsl_odeiv2_driver_apply(d, &tau, 40.0, y.data());
  gsl_odeiv2_driver_free(d);
  if (status != GSL_SUCCESS) throw std::runtime_error("biped: correction flow did not converge");
  q_flow_ = Eigen::Map<const Vec<double, 9>>(y.data());
  for (int it = 0; it < 3; ++it) {
    Vec<double, 9> dq;
    correction_flow(0, q_flow_.data(), dq.data(), const_cast<BipedMechanical*>(&mechanical_));
    q_flow_ += dq;
  }
  x_ref_ = mechanical_.contact_abscissae(q0);
}

bool Biped::closed_form_configuration(double t, const Vec<double, 2>& X, Vec<double, 9>& q) const {
  const auto& p = params_;
  const double pi = std::numbers::pi;
  const double c = std::cos(p.omega * t);
  const double kappa = pi / 10 * (1 - c);
  const double th = 4 * pi / 9 - pi / 18 * (1 - c);
  const double th3 = pi / 18 * (1 + c);
  const double th6 = -pi / 18 * (1 - c);
  // Ankles from the contacts: heel1 = ankle1 + R(th3)(-b, -h), toe2 = ankle2 + R(th6)(a, -h).
  const Eigen::Vector2d a1(X(0) - (-p.b * std::cos(th3) + p.h * std::sin(th3)),
                           0.0 - (-p.b * std::sin(th3) - p.h * std::cos(th3)));
  const Eigen::Vector2d a2(X(1) - (p.a * std::cos(th6) + p.h * std::sin(th6)),
                           0.0 - (p.a * std::sin(th6) - p.h * std::cos(th6)));
  // hip - ankle = l1 u(th1) + l2 u(th1 - kappa) = u(th1) z (complex), z = l1 + l2 e^{-i kappa}.
  const std::complex<double> z = p.l1 + p.l2 * std::polar(1.0, -kappa);
  const double rho = std::abs(z), delta = std::arg(z);
  const Eigen::Vector2d d = a2 - a1;
  const double L = d.norm();
  if (!(L < 2 * rho) || !(L > 0)) return false;
  Eigen::Vector2d n(-d(1) / L, d(0) / L);
  if (n(1) < 0) n = -n;
  const Eigen::Vector2d hip = 0.5 * (a1 + a2) + std::sqrt(rho * rho - 0.25 * L * L) * n;
  const double th1 = std::atan2(hip(1) - a1(1), hip(0) - a1(0)) - delta;
  const double th4 = std::atan2(hip(1) - a2(1), hip(0) - a2(0)) - delta;
  using M = BipedMechanical;
  q(M::qX) = hip(0) + p.lc * std::cos(th);
  q(M::qY) = hip(1) + p.lc * std::sin(th);
  q(M::qTH) = th;
  q(M::qT1) = th1;
  q(M::qT2) = th1 - kappa;
  q(M::qT3) = th3;
  q(M::qT4) = th4;
  q(M::qT5) = th4 - kappa;
  q(M::qT6) = th6;
  return true;
}

bool Biped::newton(double t, const Vec<double, 2>& X, Vec<double, 9>& q, double* residual) const {
  Vec<double, 9> f, ft;
  Eigen::Matrix<double, 9, 9> J;
  double norm = 0;
  for (int it = 0; it < 50; ++it) {
    kinematic_jacobian(mechanical_, t, q, X, f, J, ft);
    norm = f.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(norm)) break;
    const Eigen::PartialPivLU<Eigen::Matrix<double, 9, 9>> lu(J);
    const Vec<double, 9> dq = lu.solve(f);
    q -= dq;
    // Converged when the step is at round-off of q (one step past that is
    // harmless and makes the last residual round-off too).
    if (dq.lpNorm<Eigen::Infinity>() <= 1e-14 * (1 + q.lpNorm<Eigen::Infinity>())) {
      kinematic_jacobian(mechanical_, t, q, X, f, J, ft);
      norm = f.lpNorm<Eigen::Infinity>();
      if (residual) *residual = norm;
      return norm < 1e-12;
    }
  }
  if (residual) *residual = norm;
  return false;
}

bool Biped::exact_configuration(double t, const Vec<double, 2>& X, Vec<double, 9>& q) const {
  if (!closed_form_configuration(t, X, q)) return false;
  return newton(t, X, q);
}

bool Biped::exact_state(double t, const Vec<double, 2>& X, double* canonical) const {
  Vec<double, 9> q;
  if (!exact_configuration(t, X, q)) return false;
  // Differentiated equations: J v + f_t = 0 (the x_c rows have no t term).
  Vec<double, 9> f, ft;
  Eigen::Matrix<double, 9, 9> J;
  kinematic_jacobian(mechanical_, t, q, X, f, J, ft);
  const Vec<double, 9> v = J.partialPivLu().solve(-ft);
  vmap<9>(canonical) = q;
  vmap<9>(canonical + 9) = v;
  return true;
}

ProblemInfo Biped::info() const {
  ProblemInfo info;
  info.name = "biped";
  info.description =
      "seven-link planar biped, 9 absolute coordinates, 7 time-dependent holonomic + 2 integrable velocity "
      "constraints, omega = pi (Braun-Goldfarb Part II, Sec. 3.2); Winter anthropometry, 75 kg, 1.78 m; "
      "the paper's q(0) is slightly inconsistent (3 mm, 3.7e-3 rad)";
  info.coordinates = {"x", "y", "theta", "theta1", "theta2", "theta3", "theta4", "theta5", "theta6",
                      "xdot", "ydot", "thetadot", "theta1dot", "theta2dot", "theta3dot", "theta4dot",
                      "theta5dot", "theta6dot"};
  info.formulations = {{"mechanical",
                        "q = HAT centre of mass (x, y), HAT angle, thigh/shank/foot angles of legs 1 and 2; "
                        "M(q) and Q(q, v) from the seven segments",
                        mechanical_.constraints()}};
  info.has_energy = false;
  info.default_t_end = 100;
  info.reference_time = 10;
  info.reference_description =
      "exact kinematic solution (closed form + Newton on the 9 constraint equations), contact abscissae of q(0) "
      "(kept by force-based stabilization; position corrections shift them by ~5 mm)";
  return info;
}

}  // namespace cstab

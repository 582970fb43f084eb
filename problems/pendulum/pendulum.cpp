#include "problems/pendulum/pendulum.hpp"

#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>

#include <cmath>

#include "core/format.hpp"

namespace cstab {

double PendulumParameters::theta0() const { return angle * std::acos(-1.0) / 180; }

void PendulumMechanical::initial_state(Vec<double, 2>& q, Vec<double, 2>& v) const {
  q << p_.L * std::sin(p_.theta0()), -p_.L * std::cos(p_.theta0());
  v.setZero();
}

void PendulumMinimal::initial_state(Vec<double, 2>& y0) const { y0 << p_.theta0(), 0.0; }

bool PendulumMinimal::rhs(double, const Vec<double, 2>& y, Vec<double, 2>& dy) const {
  dy(0) = y(1);
  dy(1) = -p_.g / p_.L * std::sin(y(0));
  return true;
}

void PendulumMinimal::to_canonical(double, const Vec<double, 2>& y, double* c) const {
  const double s = std::sin(y(0)), co = std::cos(y(0));
  c[0] = p_.L * s;
  c[1] = -p_.L * co;
  c[2] = p_.L * co * y(1);
  c[3] = p_.L * s * y(1);
}

void PendulumMinimal::residuals(double t, const Vec<double, 2>& y, double* out) const {
  double c[4];
  to_canonical(t, y, c);
  out[0] = c[0] * c[0] + c[1] * c[1] - p_.L * p_.L;
}

// ---------------------------------------------------------------------------

ProblemInfo Pendulum::info() const {
  ProblemInfo info;
  info.name = "pendulum";
  info.description = "IFToMM benchmark A01: point mass (m = 1 kg) on a massless rod of length " + format_short(p_.L) +
                     " m under gravity, released at rest " + format_short(p_.angle) +
                     " degrees from the downward vertical";
  info.coordinates = {"x", "y", "xdot", "ydot"};
  info.formulations = {
      {"mechanical", "natural coordinates q = (x, y), M = m I, one rod-length constraint",
       PendulumMechanical::constraints()},
      {"minimal", "the angle theta from the downward vertical, theta'' = -(g / L) sin theta",
       PendulumMechanical::constraints()},
  };
  info.has_energy = true;
  info.default_t_end = 10;
  info.reference_time = 10;
  info.reference_description = "minimal-coordinate ODE (the rod angle), GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

std::vector<ParamSpec> Pendulum::problem_params() const {
  return {ranged_param("length", p_.L, 0.01, 100, "rod length L, m"),
          ranged_param("angle", p_.angle, -179, 179, "initial angle from the downward vertical, degrees (at rest)")};
}

Pendulum Pendulum::with_params(const Params& params) const {
  PendulumParameters p = p_;
  p.L = params.get("length");
  p.angle = params.get("angle");
  return Pendulum(p);
}

double Pendulum::energy(double, const double* c) const {
  return 0.5 * p_.m * (c[2] * c[2] + c[3] * c[3]) + p_.m * p_.g * c[1];
}

bool Pendulum::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

double Pendulum::closed_form_energy() const { return -p_.m * p_.g * p_.L * std::cos(p_.theta0()); }

double Pendulum::period() const {
  const double k = std::sin(std::abs(p_.theta0()) / 2);
  return 4 * std::sqrt(p_.L / p_.g) * gsl_sf_ellint_Kcomp(k, GSL_PREC_DOUBLE);
}

}  // namespace cstab

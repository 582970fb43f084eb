#include "problems/n_four_bar/n_four_bar.hpp"

#include <algorithm>
#include <cmath>

#include "core/format.hpp"

namespace cstab {

// ------------------------------------------------------------ natural coordinates
// Rows: crank i (0..N) is row i; the coupler B_i B_(i+1) (i = 0..N-1) is row N + 1 + i.

std::vector<ConstraintInfo> NFourBarNatural::constraints() {
  return {{"cranks", "holonomic", "max over the cranks of ||B_i - A_i|^2 - L^2|"},
          {"couplers", "holonomic", "max over the couplers of ||B_(i+1) - B_i|^2 - L^2|"}};
}

std::vector<ConstraintGroup> NFourBarNatural::constraint_groups() const {
  const auto info = constraints();
  return {{info[0], 0, p_.N + 1}, {info[1], p_.N + 1, 2 * p_.N + 1}};
}

void NFourBarNatural::initial_state(double* q, double* v) const {
  for (int i = 0; i <= p_.N; ++i) {
    q[2 * i] = i * p_.L;
    q[2 * i + 1] = p_.L;
    v[2 * i] = p_.speed;
    v[2 * i + 1] = 0;
  }
}

void NFourBarNatural::to_canonical(double, const double* q, const double* v, double* c) const {
  const int n = coords();
  std::copy(q, q + n, c);
  std::copy(v, v + n, c + n);
}

std::vector<ScalableModel::Entry> NFourBarNatural::mass() const {
  const int N = p_.N;
  const double m = p_.m;
  std::vector<Entry> entries;
  for (int i = 0; i <= N; ++i) {
    // The crank's m/3, and m/3 from each coupler at B_i.
    const double diag = m / 3 * (1 + (i > 0) + (i < N));
    for (int d = 0; d < 2; ++d) entries.push_back({2 * i + d, 2 * i + d, diag});
    if (i < N)
      for (int d = 0; d < 2; ++d) {
        entries.push_back({2 * i + d, 2 * (i + 1) + d, m / 6});
        entries.push_back({2 * (i + 1) + d, 2 * i + d, m / 6});
      }
  }
  return entries;
}

void NFourBarNatural::forces(double, const double*, const double*, double* Q) const {
  const int N = p_.N;
  for (int i = 0; i <= N; ++i) {
    Q[2 * i] = 0;
    Q[2 * i + 1] = -p_.m * p_.g / 2 * (1 + (i > 0) + (i < N));
  }
}

void NFourBarNatural::holonomic(const double* q, double* phi) const {
  const int N = p_.N;
  const double L2 = p_.L * p_.L;
  for (int i = 0; i <= N; ++i) {
    const double dx = q[2 * i] - i * p_.L, dy = q[2 * i + 1];
    phi[i] = dx * dx + dy * dy - L2;
  }
  for (int i = 0; i < N; ++i) {
    const double dx = q[2 * i + 2] - q[2 * i], dy = q[2 * i + 3] - q[2 * i + 1];
    phi[N + 1 + i] = dx * dx + dy * dy - L2;
  }
}

std::vector<std::pair<int, int>> NFourBarNatural::jacobian_pattern() const {
  const int N = p_.N;
  std::vector<std::pair<int, int>> pattern;
  for (int i = 0; i <= N; ++i) pattern.insert(pattern.end(), {{i, 2 * i}, {i, 2 * i + 1}});
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < 4; ++k) pattern.push_back({N + 1 + i, 2 * i + k});
  return pattern;
}

void NFourBarNatural::jacobian(const double* q, double* values) const {
  const int N = p_.N;
  double* out = values;
  for (int i = 0; i <= N; ++i) {
    *out++ = 2 * (q[2 * i] - i * p_.L);
    *out++ = 2 * q[2 * i + 1];
  }
  for (int i = 0; i < N; ++i) {
    const double dx = q[2 * i + 2] - q[2 * i], dy = q[2 * i + 3] - q[2 * i + 1];
    *out++ = -2 * dx;
    *out++ = -2 * dy;
    *out++ = 2 * dx;
    *out++ = 2 * dy;
  }
}

void NFourBarNatural::gamma(const double*, const double* v, double* gamma) const {
  const int N = p_.N;
  for (int i = 0; i <= N; ++i) gamma[i] = 2 * (v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1]);
  for (int i = 0; i < N; ++i) {
    const double dx = v[2 * i + 2] - v[2 * i], dy = v[2 * i + 3] - v[2 * i + 1];
    gamma[N + 1 + i] = 2 * (dx * dx + dy * dy);
  }
}

double NFourBarNatural::energy(double, const double* q, const double* v) const {
  const int N = p_.N;
  const double m = p_.m;
  double kinetic = 0, potential = 0;
  for (int i = 0; i <= N; ++i) {
    const double share = 1 + (i > 0) + (i < N);  // bar ends at B_i
    kinetic += m / 3 * share * (v[2 * i] * v[2 * i] + v[2 * i + 1] * v[2 * i + 1]);
    if (i < N) kinetic += m / 3 * (v[2 * i] * v[2 * i + 2] + v[2 * i + 1] * v[2 * i + 3]);
    potential += m * p_.g / 2 * share * q[2 * i + 1];
  }
  return kinetic / 2 + potential;
}

// ------------------------------------------------------------ minimal coordinate

void NFourBarMinimal::initial_state(Vec<double, 2>& y0) const {
  // B0 = (L cos theta, L sin theta): vertical, and x' = -L sin(theta) theta' = speed.
  y0 << std::acos(-1.0) / 2, -p_.speed / p_.L;
}

bool NFourBarMinimal::rhs(double, const Vec<double, 2>& y, Vec<double, 2>& dy) const {
  dy(0) = y(1);
  dy(1) = -p_.weight() * p_.L * std::cos(y(0)) / p_.inertia();
  return true;
}

void NFourBarMinimal::to_canonical(double, const Vec<double, 2>& y, double* c) const {
  const int n = 2 * (p_.N + 1);
  const double s = std::sin(y(0)), co = std::cos(y(0));
  for (int i = 0; i <= p_.N; ++i) {
    c[2 * i] = i * p_.L + p_.L * co;
    c[2 * i + 1] = p_.L * s;
    c[n + 2 * i] = -p_.L * s * y(1);
    c[n + 2 * i + 1] = p_.L * co * y(1);
  }
}

void NFourBarMinimal::residuals(double, const Vec<double, 2>& y, double* out) const {
  // The natural rows at the positions of to_canonical (round-off only).
  const double x = p_.L * std::cos(y(0)), s = p_.L * std::sin(y(0)), L2 = p_.L * p_.L;
  out[0] = out[1] = 0;
  for (int i = 0; i <= p_.N; ++i) {
    const double xi = i * p_.L + x;
    out[0] = std::max(out[0], std::abs((xi - i * p_.L) * (xi - i * p_.L) + s * s - L2));
    if (i < p_.N) {
      const double dx = ((i + 1) * p_.L + x) - xi;
      out[1] = std::max(out[1], std::abs(dx * dx - L2));
    }
  }
}

// ------------------------------------------------------------ the problem

ProblemInfo NFourBar::info() const {
  ProblemInfo info;
  info.name = "n-four-bar";
  info.description = "IFToMM benchmark A02: " + std::to_string(p_.N) + " four-bar loops sharing their bars (" +
                     std::to_string(2 * p_.N + 1) +
                     " bars of 1 m and 1 kg), passing singular positions where every bar is horizontal";
  const int n = 2 * (p_.N + 1);
  info.coordinates.resize(size_t(2 * n));
  for (int i = 0; i <= p_.N; ++i) {
    const std::string b = "_B" + std::to_string(i);
    info.coordinates[size_t(2 * i)] = "x" + b;
    info.coordinates[size_t(2 * i + 1)] = "y" + b;
    info.coordinates[size_t(n + 2 * i)] = "xdot" + b;
    info.coordinates[size_t(n + 2 * i + 1)] = "ydot" + b;
  }
  info.formulations = {
      {"natural", "natural coordinates q = (x, y) of B0..BN, runtime size, constant banded mass, 2N + 1 bar rows",
       NFourBarNatural::constraints()},
      {"minimal", "the crank angle theta, I theta'' = -W L cos theta", NFourBarNatural::constraints()},
  };
  info.has_energy = true;
  info.default_t_end = 20;
  info.reference_time = 20;
  info.reference_description = "minimal-coordinate ODE (the crank angle), GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

std::vector<ParamSpec> NFourBar::problem_params() const {
  return {ranged_param("N", p_.N, 1, 1000, "the number of four-bar loops (2N + 1 bars)", /*integer=*/true)};
}

NFourBar NFourBar::with_params(const Params& params) const {
  NFourBarParameters p = p_;
  p.N = int(params.get("N"));
  return NFourBar(p);
}

double NFourBar::energy(double t, const double* c) const { return natural_.energy(t, c, c + 2 * (p_.N + 1)); }

bool NFourBar::reference(double t, double* canonical) const { return reference_.at(t, canonical); }

}  // namespace cstab

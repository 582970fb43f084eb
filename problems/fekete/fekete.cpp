#include "problems/fekete/fekete.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cstab {

// ------------------------------------------------------------ cartesian coordinates

std::vector<ConstraintInfo> FeketeCartesian::constraints() {
  return {{"sphere", "holonomic", "max over the particles of ||p_i|^2 - 1|"}};
}

std::vector<ConstraintGroup> FeketeCartesian::constraint_groups() const { return {{constraints()[0], 0, p_.N}}; }

namespace {

void place(double longitude, double latitude, double* p) {
  p[0] = std::cos(longitude) * std::cos(latitude);
  p[1] = std::sin(longitude) * std::cos(latitude);
  p[2] = std::sin(latitude);
}

}  // namespace

void FeketeCartesian::initial_state(double* q, double* v) const {
  const int N = p_.N;
  constexpr double pi = std::numbers::pi;
  if (N == 20) {
    // The Test Set's four rings (particles numbered from 1 there).
    for (int i = 1; i <= 20; ++i) {
      double a, b;
      if (i <= 3) {
        a = 2 * pi * i / 3 + pi / 13, b = 3 * pi / 8;
      } else if (i <= 10) {
        a = 2 * pi * (i - 3) / 7 + pi / 29, b = pi / 8;
      } else if (i <= 16) {
        a = 2 * pi * (i - 10) / 6 + pi / 7, b = -2 * pi / 15;
      } else {
        a = 2 * pi * (i - 17) / 4 + pi / 17, b = -3 * pi / 10;
      }
      place(a, b, q + 3 * (i - 1));
    }
  } else {
    // A Fibonacci spiral (nearly even), each particle moved by a quarter of
    // the mean spacing s = sqrt(4 pi / N) in latitude and longitude so that
    // the particles start away from rest (nearest pair >= 0.35 s for
    // N <= 1000, tests/unit/test_fekete.cpp).
    const double golden = pi * (3 - std::sqrt(5.0));
    const double s = std::sqrt(4 * pi / N);
    for (int i = 0; i < N; ++i) {
      const double z = 1 - (2.0 * i + 1) / N;
      const double latitude = std::clamp(std::asin(z) + 0.25 * s * std::sin(2.3 * i + 0.7), -1.5, 1.5);
      place(golden * i + 0.25 * s * std::cos(1.7 * i) / std::max(std::cos(latitude), 0.2), latitude, q + 3 * i);
    }
  }
  std::fill(v, v + 3 * N, 0.0);
}

void FeketeCartesian::to_canonical(double, const double* q, const double* v, double* c) const {
  const int n = coords();
  std::copy(q, q + n, c);
  std::copy(v, v + n, c + n);
}

std::vector<ScalableModel::Entry> FeketeCartesian::mass() const {
  std::vector<Entry> entries;
  for (int j = 0; j < coords(); ++j) entries.push_back({j, j, 1.0});
  return entries;
}

void FeketeCartesian::forces(double, const double* q, const double* v, double* Q) const {
  const int N = p_.N;
  for (int j = 0; j < 3 * N; ++j) Q[j] = -p_.alpha * v[j];
  for (int i = 0; i < N; ++i) {
    const double* pi = q + 3 * i;
    for (int j = i + 1; j < N; ++j) {
      const double* pj = q + 3 * j;
      const double d0 = pi[0] - pj[0], d1 = pi[1] - pj[1], d2 = pi[2] - pj[2];
      const double w = 1 / (d0 * d0 + d1 * d1 + d2 * d2);
      Q[3 * i] += w * d0, Q[3 * i + 1] += w * d1, Q[3 * i + 2] += w * d2;
      Q[3 * j] -= w * d0, Q[3 * j + 1] -= w * d1, Q[3 * j + 2] -= w * d2;
    }
  }
}

void FeketeCartesian::holonomic(const double* q, double* phi) const {
  for (int i = 0; i < p_.N; ++i) {
    const double* p = q + 3 * i;
    phi[i] = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - 1;
  }
}

std::vector<std::pair<int, int>> FeketeCartesian::jacobian_pattern() const {
  std::vector<std::pair<int, int>> pattern;
  for (int i = 0; i < p_.N; ++i)
    for (int k = 0; k < 3; ++k) pattern.push_back({i, 3 * i + k});
  return pattern;
}

void FeketeCartesian::jacobian(const double* q, double* values) const {
  for (int j = 0; j < 3 * p_.N; ++j) values[j] = 2 * q[j];
}

void FeketeCartesian::gamma(const double*, const double* v, double* gamma) const {
  for (int i = 0; i < p_.N; ++i) {
    const double* w = v + 3 * i;
    gamma[i] = 2 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
}

double FeketeCartesian::lyapunov(const double* q, const double* v) const {
  const int N = p_.N;
  double kinetic = 0, potential = 0;
  for (int j = 0; j < 3 * N; ++j) kinetic += v[j] * v[j] / 2;
  for (int i = 0; i < N; ++i)
    for (int j = i + 1; j < N; ++j) {
      const double d0 = q[3 * i] - q[3 * j], d1 = q[3 * i + 1] - q[3 * j + 1], d2 = q[3 * i + 2] - q[3 * j + 2];
      potential -= std::log(d0 * d0 + d1 * d1 + d2 * d2) / 2;
    }
  return kinetic + potential;
}

void FeketeCartesian::closed_form_rhs(const double* y, double* dydt) const {
  // Per particle: a = F + lambda p with p . a + |v|^2 = 0 (the row twice
  // differentiated), F the applied force. No KKT matrix is formed.
  const int n = coords();
  const double* q = y;
  const double* v = y + n;
  double* a = dydt + n;
  std::copy(v, v + n, dydt);
  forces(0, q, v, a);
  for (int i = 0; i < p_.N; ++i) {
    const double* p = q + 3 * i;
    const double* w = v + 3 * i;
    double* ai = a + 3 * i;
    const double pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    const double lambda = -(p[0] * ai[0] + p[1] * ai[1] + p[2] * ai[2] + w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) / pp;
    for (int k = 0; k < 3; ++k) ai[k] += lambda * p[k];
  }
}

// ------------------------------------------------------------ the problem

const std::vector<double>& Fekete::test_set_solution() {
  // The Test Set's y(1..120) at t = 1000 (its routine feksoln, RADAU5 at
  // rtol = atol = h0 = 1e-12): p_1 .. p_20, then q_1 .. q_20, three
  // components each. Its lambda_i (all -4.75) and mu_i (about 1e-18) are
  // multipliers, not part of cstab's canonical state.
  static const std::vector<double> y = {
      -0.4070263380333202e+00, 0.3463758772791802e+00,  0.8451942450030429e+00,  0.7752934752521549e-01,
      -0.2628662719972299e+00, 0.9617122871829146e+00,  0.7100577833343567e+00,  0.1212948055586120e+00,
      0.6936177005172217e+00,  0.2348267744557627e+00,  0.7449277976923311e+00,  0.6244509285956391e+00,
      -0.4341114738782885e+00, 0.8785430442262876e+00,  0.1992720444237660e+00,  -0.9515059600312596e+00,
      0.2203508762787005e+00,  0.2146669498274008e+00,  -0.6385191643609878e+00, -0.4310833259390688e+00,
      0.6375425027722121e+00,  -0.1464175087914336e+00, -0.9380871635228862e+00, 0.3139337298744690e+00,
      0.5666974065069942e+00,  -0.6739221885076542e+00, 0.4740073135462156e+00,  0.9843259538440293e+00,
      -0.1696995357819996e+00, -0.4800504290609090e-01, 0.1464175087914331e+00,  0.9380871635228875e+00,
      -0.3139337298744656e+00, -0.7092757549979014e+00, 0.5264062637139616e+00,  -0.4688542938854929e+00,
      -0.8665731819284478e+00, -0.4813878059756024e+00, -0.1315929352982178e+00, -0.2347897778700538e+00,
      -0.8594340408013130e+00, -0.4541441287957579e+00, 0.5530976940074118e+00,  -0.7674370265615124e+00,
      -0.3242273140037833e+00, 0.7711050969896927e+00,  0.6357041816577034e+00,  0.3573685519777001e-01,
      0.7103951209379591e+00,  0.2403570431280519e+00,  -0.6614886725910596e+00, -0.3038208738735660e-01,
      0.4501923293640461e+00,  -0.8924145871442046e+00, -0.5772996158107093e+00, -0.1766763414971813e+00,
      -0.7971892020969544e+00, 0.2414481766969039e+00,  -0.3416456818373135e+00, -0.9082846503446250e+00,
      0.2409619682166627e-15,  -0.1139818460497816e-15, 0.1627536276556335e-15,  0.1745651819597609e-15,
      -0.1914278710633076e-15, -0.6639600671806291e-16, 0.1708576733899083e-15,  -0.2277602521390053e-15,
      -0.1350782790950654e-15, 0.2411941341109454e-15,  -0.1438238671800488e-15, 0.8087033550666644e-16,
      0.1618239105233347e-15,  0.1837556152070701e-16,  0.2715177369929503e-15,  0.7930078658689191e-16,
      0.7482020588342764e-16,  0.2746974939098084e-15,  0.8849338913035911e-16,  -0.5940734725324115e-16,
      0.4845984056889910e-16,  -0.3728835248155620e-16, -0.4600332954062859e-16, -0.1548568884846698e-15,
      0.2507541692375411e-16,  -0.1560155223230823e-15, -0.2517946296860555e-15, -0.3739779361502470e-16,
      -0.1381663620885020e-15, -0.2784051540342329e-15, 0.6624397102887671e-16,  0.4226207488883120e-16,
      0.1571821772296610e-15,  -0.4112243677286995e-16, 0.1939960344265876e-15,  0.2800184977692136e-15,
      -0.9189023375328813e-16, 0.1392943179389155e-15,  0.9556003995587458e-16,  -0.2234188557495892e-15,
      0.1276804778190781e-15,  -0.1261196211463950e-15, -0.1887754149742397e-15, -0.2140788698695373e-16,
      -0.2713591291421657e-15, 0.1107887633060814e-15,  -0.1318443715631340e-15, -0.4521275683078691e-16,
      -0.1277688851278605e-15, 0.4850914012115388e-16,  -0.1195891666741192e-15, -0.1569641653843750e-15,
      0.1856239009452638e-15,  0.9898466095646496e-16,  -0.2068030800303723e-15, 0.2451470336752085e-15,
      0.9542986459336358e-16,  -0.2456074075580993e-15, 0.1532475480661800e-15,  -0.1229326332276474e-15,
  };
  return y;
}

ReferenceCache Fekete::make_cache() const {
  const FeketeCartesian model = cartesian_;
  const int n = 6 * p_.N;
  return ReferenceCache(
      n, n, [model](double, const double* y, double* dydt) { model.closed_form_rhs(y, dydt); },
      [model](double* y) { model.initial_state(y, y + model.coords()); },
      [n](double, const double* y, double* c) { std::copy(y, y + n, c); });
}

bool Fekete::reference(double t, double* canonical) const {
  if (p_.N == 20 && t == kTestSetTime) {
    const auto& y = test_set_solution();
    std::copy(y.begin(), y.end(), canonical);
    return true;
  }
  return reference_.at(t, canonical);
}

ProblemInfo Fekete::info() const {
  ProblemInfo info;
  info.name = "fekete";
  info.description = "IVP Test Set fekete: " + std::to_string(p_.N) +
                     " charged particles on the unit sphere, damped, coming to rest at Fekete points";
  const int n = 3 * p_.N;
  info.coordinates.resize(size_t(2 * n));
  const char* axis[] = {"x", "y", "z"};
  for (int i = 0; i < p_.N; ++i)
    for (int k = 0; k < 3; ++k) {
      const std::string name = std::string(axis[k]) + "_" + std::to_string(i + 1);
      info.coordinates[size_t(3 * i + k)] = name;
      info.coordinates[size_t(n + 3 * i + k)] = name.substr(0, 1) + "dot" + name.substr(1);
    }
  info.formulations = {{"cartesian",
                        "positions p_i in R^3, M = I, a row |p_i|^2 - 1 per particle, runtime size (3N coordinates)",
                        FeketeCartesian::constraints()}};
  info.has_energy = false;
  info.default_t_end = kDefaultHorizon;
  info.reference_time = kDefaultHorizon;
  info.reference_description =
      p_.N == 20 ? "the IVP Test Set's published solution at t = 1000 (RADAU5, 1e-12); at other times the closed-form "
                   "per-particle ODE, GSL rk8pd, rtol = atol = 1e-13"
                 : "the closed-form per-particle ODE (each multiplier solved by hand), GSL rk8pd, rtol = atol = 1e-13";
  return info;
}

std::vector<ParamSpec> Fekete::problem_params() const {
  return {ranged_param("N", p_.N, 2, 1000, "the number of particles (3N coordinates, N rows)", /*integer=*/true)};
}

Fekete Fekete::with_params(const Params& params) const {
  FeketeParameters p = p_;
  p.N = int(params.get("N"));
  return Fekete(p);
}

}  // namespace cstab

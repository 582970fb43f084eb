#include "harness/conformance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/format.hpp"
#include "harness/integrator.hpp"

namespace cstab {

RunConfig conformance_config(const Problem& problem, const MethodInfo& method, double t_end, bool accuracy) {
  const ConformanceSettings& c = method.conformance;
  RunConfig cfg;
  cfg.problem = problem.info().name;
  cfg.method = method.name;
  cfg.t_end = t_end;
  cfg.ref_time = t_end;
  cfg.write_series = false;
  cfg.integrator = c.integrator;
  cfg.params = c.params;
  if (find_integrator(c.integrator).fixed_step) {
    cfg.step.step = std::min(c.step, t_end / 2000);
    if (problem.info().resolution_step > 0) cfg.step.step = std::min(cfg.step.step, problem.info().resolution_step);
    if (accuracy && c.accuracy_steps > 0) cfg.step.step = std::min(cfg.step.step, t_end / c.accuracy_steps);
  } else {
    cfg.step.rtol = cfg.step.atol = c.tol;
  }
  if (c.time_scale_steps > 0) {
    const ParamSpec* gain = find_gain(method.params);
    if (!gain || gain->role != ParamRole::kTimeScale)
      throw std::logic_error(method.name + ": conformance time_scale_steps needs a time-scale gain");
    cfg.params.emplace_back(gain->name, std::to_string(c.time_scale_steps * cfg.step.step));
  }
  return cfg;
}

double initial_residual(const Problem& problem, const RunConfig& cfg) {
  const auto specs = problem.method_params(cfg.method, cfg.formulation);
  auto form = problem.make(cfg.method, cfg.formulation, Params::resolve(specs, cfg.params, cfg.method));
  std::vector<double> y(form->dimension()), r(form->constraints().size());
  form->initial_state(y.data());
  form->residuals(0.0, y.data(), r.data());
  double worst = 0;
  for (double v : r) worst = std::max(worst, std::abs(v));
  return worst;
}

ConformanceRun run_conformance(const Problem& problem, const MethodInfo& method) {
  ConformanceRun c;
  c.t_end = std::min(2.0, problem.info().default_t_end);
  RunConfig probe = conformance_config(problem, method, c.t_end, false);
  if (problem.why_not("none").empty()) {
    probe.method = "none";
    probe.params.clear();
    probe.formulation.clear();
  }
  c.start_residual = initial_residual(problem, probe);
  c.consistent_start = c.start_residual < 1e-10;
  c.config = conformance_config(problem, method, c.t_end, c.consistent_start);
  c.result = run_case(problem, c.config, "");
  return c;
}

double derivative_consistency(const Problem& problem, std::string* detail) {
  const std::string why = problem.why_not("none");
  if (!why.empty()) {
    *detail = "needs the method `none` (" + why + ")";
    return std::nan("");
  }
  auto f = problem.make("none", "", Params::resolve(problem.method_params("none", ""), {}, "none"));
  const int n = f->dimension();
  const auto& rows = f->constraints();
  const size_t m = rows.size();
  if (m == 0) {
    *detail = "no constraint rows";
    return 0;
  }
  std::vector<double> y(n), f0(n), fp(n), fm(n), g(n), yp(n), ym(n), r0(m), rp(m), rm(m);
  double worst = 0;
  constexpr double kS = 1e-4, kD = 1e-6;
  for (int state = 0; state < 2; ++state) {
    f->initial_state(y.data());
    if (state == 1) perturb_initial_state(1e-2, n, y.data());
    const double t = 0.5;  // not 0: time-dependent rows move in both directions
    if (!f->rhs(t, y.data(), f0.data())) {
      *detail = "`none` cannot evaluate its right-hand side: " + f->failure_reason();
      return std::numeric_limits<double>::infinity();
    }
    for (int i = 0; i < n; ++i) yp[i] = y[i] + kD * f0[i], ym[i] = y[i] - kD * f0[i];
    if (!f->rhs(t + kD, yp.data(), fp.data()) || !f->rhs(t - kD, ym.data(), fm.data())) {
      *detail = "`none` cannot evaluate its right-hand side near the state: " + f->failure_reason();
      return std::numeric_limits<double>::infinity();
    }
    double scale = 1;
    for (int i = 0; i < n; ++i) {
      g[i] = (fp[i] - fm[i]) / (2 * kD);
      scale = std::max({scale, 1 + std::abs(f0[i]), 1 + std::abs(g[i])});
    }
    for (int i = 0; i < n; ++i) {
      yp[i] = y[i] + kS * f0[i] + 0.5 * kS * kS * g[i];
      ym[i] = y[i] - kS * f0[i] + 0.5 * kS * kS * g[i];
    }
    f->residuals(t, y.data(), r0.data());
    f->residuals(t + kS, yp.data(), rp.data());
    f->residuals(t - kS, ym.data(), rm.data());
    for (size_t k = 0; k < m; ++k) {
      const bool holonomic = rows[k].kind.rfind("holonomic", 0) == 0;
      const double d = holonomic ? (rp[k] - 2 * r0[k] + rm[k]) / (kS * kS) : (rp[k] - rm[k]) / (2 * kS);
      const double rel = std::abs(d) / scale;
      if (!(rel <= worst)) {
        worst = std::isnan(rel) ? std::numeric_limits<double>::infinity() : rel;
        *detail = std::string(holonomic ? "d2/dt2 " : "d/dt ") + rows[k].name + " = " + format_3g(d) +
                  " along the flow (relative " + format_3g(rel) + ", at the " +
                  (state == 0 ? "initial" : "perturbed") + " state)";
      }
    }
  }
  return worst;
}

}  // namespace cstab

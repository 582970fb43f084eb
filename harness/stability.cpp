#include "harness/stability.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <complex>

#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "linalg/dense.hpp"

namespace cstab {

namespace {

// Spectral radius of the one-step recurrence of a scheme for y' = mu y, z = h mu.
double amplification(const std::string& integrator, double z) {
  if (integrator == "euler") return std::abs(1 + z);
  if (integrator == "rk4") return std::abs(1 + z + z * z / 2 + z * z * z / 6 + z * z * z * z / 24);
  if (integrator == "adams") {
    // PECE with AB4 predictor and AM4 corrector, f re-evaluated at the
    // corrected point: y_{n+1} = y_n + z/24 (9 p + 19 y_n - 5 y_{n-1} + y_{n-2}),
    // p = y_n + z/24 (55 y_n - 59 y_{n-1} + 37 y_{n-2} - 9 y_{n-3}).
    // Coefficients of y_{n+1} = c0 y_n + c1 y_{n-1} + c2 y_{n-2} + c3 y_{n-3}.
    const double a = z / 24;
    const double k0 = 1 + 9 * a * (1 + 55 * a) + 19 * a;
    const double k1 = 9 * a * (-59 * a) - 5 * a;
    const double k2 = 9 * a * (37 * a) + a;
    const double k3 = 9 * a * (-9 * a);
    Eigen::Matrix4d companion = Eigen::Matrix4d::Zero();
    companion(0, 0) = k0;
    companion(0, 1) = k1;
    companion(0, 2) = k2;
    companion(0, 3) = k3;
    companion(1, 0) = companion(2, 1) = companion(3, 2) = 1;
    return linalg::spectral_radius_of(companion);
  }
  return NAN;
}

}  // namespace

double real_stability_boundary(const std::string& integrator) {
  if (!find_integrator(integrator).fixed_step) return 0;
  // Walk left from 0 until the amplification exceeds 1, then bisect.
  double inside = -1e-6, outside = 0;
  for (double x = 0.01;; x += 0.01) {
    if (amplification(integrator, -x) > 1 + 1e-12) {
      outside = -x;
      inside = -(x - 0.01);
      break;
    }
    if (x > 100) return INFINITY;
  }
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (inside + outside);
    (amplification(integrator, mid) > 1 + 1e-12 ? outside : inside) = mid;
  }
  return -inside;
}

ParamSpec gain_spec(const Problem& problem, const StabilityConfig& cfg) {
  const auto specs = problem.method_params(cfg.base.method, cfg.base.formulation);
  if (cfg.gain_param.empty()) {
    if (const ParamSpec* g = find_gain(specs)) return *g;
    throw UsageError("--gain-param: method '" + cfg.base.method + "' declares no gain");
  }
  for (const auto& s : specs)
    if (s.name == cfg.gain_param) return s;
  throw UsageError("--gain-param " + cfg.gain_param + ": method '" + cfg.base.method + "' has no such parameter");
}

void apply_gain(RunConfig& rc, const ParamSpec& spec, double gain) {
  const std::string value = format_short(gain);
  rc.params.emplace_back(spec.name, value);
  for (const auto& tied : spec.swept_with) rc.params.emplace_back(tied, value);  // e.g. beta = alpha
}

namespace {

StabilityPoint run_point(const Problem& problem, const StabilityConfig& cfg, double h, double gain) {
  const ParamSpec spec = gain_spec(problem, cfg);
  RunConfig rc = cfg.base;
  rc.step.step = h;
  rc.write_series = false;
  rc.ref_time = 0;
  apply_gain(rc, spec, gain);
  const RunResult r = run_case(problem, rc, "");
  StabilityPoint p;
  p.step = h;
  p.gain = gain;
  p.rate = spec.role == ParamRole::kSetting ? NAN : gain_rate(spec, gain);
  p.status = r.status;
  p.max_residual = r.max_residual;
  p.final_residual = r.final_residual;
  p.fail_time = r.fail_time;
  return p;
}

}  // namespace

bool boundary_in_rate(const ParamSpec& spec, const std::string& integrator) {
  const double theory = real_stability_boundary(integrator);
  return spec.role != ParamRole::kSetting && theory > 0 && std::isfinite(theory);
}

std::vector<StabilityPoint> stability_map(const Problem& problem, const StabilityConfig& cfg) {
  std::vector<StabilityPoint> out;
  for (double h : cfg.steps)
    for (double g : cfg.gains) out.push_back(run_point(problem, cfg, h, g));
  return out;
}

std::vector<StabilityBoundary> stability_boundaries(const Problem& problem, const StabilityConfig& cfg) {
  std::vector<StabilityBoundary> out;
  const double theory = real_stability_boundary(cfg.base.integrator);
  const ParamSpec spec = gain_spec(problem, cfg);
  for (double h : cfg.steps) {
    // Bracket in h * rate around the theory, then bisect in log space.
    double lo = 0.25 * theory, hi = 4 * theory;  // in units of h * rate
    auto stable = [&](double hr) {
      const double rate = hr / h;
      const double gain = spec.role == ParamRole::kTimeScale ? 1.0 / rate : rate;
      return run_point(problem, cfg, h, gain).status == "ok";
    };
    if (!stable(lo) || stable(hi)) {
      out.push_back({h, NAN, NAN, NAN, theory});
      continue;
    }
    for (int i = 0; i < cfg.bisection_iterations; ++i) {
      const double mid = std::sqrt(lo * hi);
      (stable(mid) ? lo : hi) = mid;
    }
    out.push_back({h, lo / h, hi / h, std::sqrt(lo * hi), theory});
  }
  return out;
}

std::vector<StepBoundary> step_boundaries(const Problem& problem, const StabilityConfig& cfg,
                                          const std::vector<StabilityPoint>& map) {
  std::vector<double> steps = cfg.steps;
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  std::vector<StepBoundary> out;
  for (double g : cfg.gains) {
    auto stable_on_grid = [&](double h) {
      for (const auto& p : map)
        if (p.step == h && p.gain == g) return p.status == "ok";
      return run_point(problem, cfg, h, g).status == "ok";
    };
    StepBoundary b{g, NAN, NAN};
    for (double h : steps) {
      if (!stable_on_grid(h)) {
        b.unstable_step = h;
        break;
      }
      b.stable_step = h;
    }
    if (std::isfinite(b.stable_step) && std::isfinite(b.unstable_step))
      for (int i = 0; i < cfg.bisection_iterations; ++i) {
        const double mid = std::sqrt(b.stable_step * b.unstable_step);
        (run_point(problem, cfg, mid, g).status == "ok" ? b.stable_step : b.unstable_step) = mid;
      }
    out.push_back(b);
  }
  return out;
}

}  // namespace cstab

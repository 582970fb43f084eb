// The characteristic rates of every problem (issue 22's gain rule scaled by a
// property of the problem, docs/measurements.md): the spectral radius of the
// Jacobian of the unstabilized index-1 ODE (method `none`), by central
// differences, at the initial state and at 21 states along the trajectory
// to the reference time (t_end where there is none), followed with
// `projection` (the index-1 ODE kept on the constraints) on the harness's RK4
// with a step below 1 / (the rate at t0) and at most T / 20000. The
// physical modes give eigenvalues +-i omega; the drift modes of the
// unstabilized ODE are zeros. One CSV row per problem:
//   problem,formulation,rate_t0,rate_min,rate_median,rate_gmean,rate_max
//   cmake --build build/release --target cstab-problem-rates
//   build/release/bench/cstab-problem-rates > rates.csv
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "core/formulation.hpp"
#include "core/params.hpp"
#include "harness/integrator.hpp"
#include "linalg/dense.hpp"
#include "problems/registry.hpp"

namespace {

using namespace cstab;

// The method at its default parameters on its default formulation (nullptr
// if it does not apply to `p`).
std::unique_ptr<Formulation> make_default(const Problem& p, const std::string& method) {
  if (!p.why_not(method).empty()) return nullptr;
  return p.make(method, "", Params::resolve(p.method_params(method, ""), {}, method));
}

class RateProbe {
 public:
  explicit RateProbe(Formulation& f)
      : f_(f), n_(f.dimension()), plus_(n_), minus_(n_), fp_(n_), fm_(n_), jacobian_(n_ * n_) {}

  double at(double t, const std::vector<double>& y) {
    for (int j = 0; j < n_; ++j) {
      const double d = 1e-6 * std::max(1.0, std::abs(y[j]));
      plus_ = y, minus_ = y;
      plus_[j] += d, minus_[j] -= d;
      if (!f_.rhs(t, plus_.data(), fp_.data()) || !f_.rhs(t, minus_.data(), fm_.data())) return NAN;
      for (int i = 0; i < n_; ++i) jacobian_[i + j * n_] = (fp_[i] - fm_[i]) / (2 * d);
    }
    return linalg::spectral_radius(jacobian_.data(), n_);
  }

 private:
  Formulation& f_;
  int n_;
  std::vector<double> plus_, minus_, fp_, fm_, jacobian_;
};

void print_rates(const Problem& p) {
  auto bare = make_default(p, "none");
  auto follow = make_default(p, "projection");
  if (!bare || !follow || follow->formulation_name() != bare->formulation_name() ||
      follow->dimension() != bare->dimension()) {
    std::fprintf(stderr, "problem-rates: %s: no index-1 ODE (none, projection) on one formulation; left out\n",
                 p.info().name.c_str());
    return;
  }
  const std::string formulation = bare->formulation_name();
  const int n = bare->dimension();
  std::vector<double> y(n);
  follow->initial_state(y.data());
  RateProbe probe(*bare);
  const double rate0 = probe.at(0, y);
  const double horizon = p.info().reference_time > 0 ? p.info().reference_time : p.info().default_t_end;
  constexpr int kSamples = 20;
  const long steps_per_sample =
      std::max(1000L, long(std::ceil(horizon * std::max(rate0, 0.0) / kSamples)));  // h * rate0 <= 1
  const double h = horizon / double(kSamples * steps_per_sample);
  auto rk4 = make_integrator("rk4", StepSettings{h, 0, 0});
  rk4->start(*follow, 0, y.data());
  std::vector<double> rates = {rate0};
  for (int s = 1; s <= kSamples; ++s) {
    const double t_sample = horizon * s / kSamples;
    bool ok = true;
    while (ok && rk4->t() < t_sample - 0.5 * h) {
      ok = rk4->step(t_sample) == StepOutcome::kOk &&
           !(follow->has_post_step() && follow->post_step(rk4->t(), rk4->y()) && !rk4->notify_modified()) &&
           std::all_of(rk4->y(), rk4->y() + n, [](double x) { return std::isfinite(x); });
    }
    if (!ok) break;
    y.assign(rk4->y(), rk4->y() + n);
    rates.push_back(probe.at(rk4->t(), y));
  }
  std::vector<double> sorted = rates;
  std::sort(sorted.begin(), sorted.end());
  double log_sum = 0;
  for (double r : sorted) log_sum += std::log(std::max(r, 1e-12));
  std::printf("%s,%s,%.6g,%.6g,%.6g,%.6g,%.6g\n", p.info().name.c_str(), formulation.c_str(), rate0, sorted.front(),
              sorted[sorted.size() / 2], std::exp(log_sum / double(sorted.size())), sorted.back());
  if (rates.size() != kSamples + 1)
    std::fprintf(stderr, "problem-rates: %s: the trajectory stopped being finite after %zu of %d samples\n",
                 p.info().name.c_str(), rates.size() - 1, kSamples);
}

}  // namespace

int main() {
  try {
    std::printf("problem,formulation,rate_t0,rate_min,rate_median,rate_gmean,rate_max\n");
    for (const auto& p : all_problems()) print_rates(*p);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "problem-rates: %s\n", e.what());
    return 1;
  }
}

// A problem's reference solution from an independent minimal-coordinate ODE,
// integrated from t = 0 by GSL rk8pd at rtol = atol = 1e-13 and cached per
// requested time (thread-safe; copies of a problem share the cache).
#pragma once

#include <functional>
#include <memory>

#include "core/vec.hpp"

namespace cstab {

class ReferenceCache {
 public:
  using Rhs = std::function<void(double t, const double* y, double* dydt)>;
  using Initial = std::function<void(double* y)>;
  using Canonical = std::function<void(double t, const double* y, double* canonical)>;

  ReferenceCache(int states, int canonical, Rhs rhs, Initial initial, Canonical to_canonical);
  // The canonical state at t; false if the integration failed.
  bool at(double t, double* canonical) const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// For a minimal model with kStates, rhs(t, Vec, Vec&), initial_state(Vec&)
// and to_canonical(t, Vec, double*); the cache keeps a copy of the model.
template <class Minimal>
ReferenceCache reference_cache_of(const Minimal& model, int canonical) {
  constexpr int n = Minimal::kStates;
  return ReferenceCache(
      n, canonical,
      [model](double t, const double* y, double* dydt) {
        Vec<double, n> dy;
        model.rhs(t, vmap<n>(y).eval(), dy);
        vmap<n>(dydt) = dy;
      },
      [model](double* y) {
        Vec<double, n> y0;
        model.initial_state(y0);
        vmap<n>(y) = y0;
      },
      [model](double t, const double* y, double* c) { model.to_canonical(t, vmap<n>(y).eval(), c); });
}

}  // namespace cstab

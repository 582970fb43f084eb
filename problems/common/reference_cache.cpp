#include "problems/common/reference_cache.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <vector>

namespace cstab {

struct ReferenceCache::Impl {
  int states, canonical;
  Rhs rhs;
  Initial initial;
  Canonical to_canonical;
  std::mutex mutex;
  std::map<double, std::vector<double>> cached;  // t -> canonical state
};

ReferenceCache::ReferenceCache(int states, int canonical, Rhs rhs, Initial initial, Canonical to_canonical)
    : impl_(std::make_shared<Impl>()) {
  impl_->states = states;
  impl_->canonical = canonical;
  impl_->rhs = std::move(rhs);
  impl_->initial = std::move(initial);
  impl_->to_canonical = std::move(to_canonical);
}

namespace {
int gsl_rhs(double t, const double y[], double dydt[], void* rhs) {
  (*static_cast<const ReferenceCache::Rhs*>(rhs))(t, y, dydt);
  return GSL_SUCCESS;
}
}  // namespace

bool ReferenceCache::at(double t, double* canonical) const {
  Impl& m = *impl_;
  std::lock_guard<std::mutex> lock(m.mutex);
  auto it = m.cached.find(t);
  if (it == m.cached.end()) {
    gsl_odeiv2_system sys{gsl_rhs, nullptr, static_cast<size_t>(m.states), &m.rhs};
    gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-6, 1e-13, 1e-13);
    std::vector<double> y(m.states);
    m.initial(y.data());
    double t0 = 0;
    const int status = gsl_odeiv2_driver_apply(d, &t0, t, y.data());
    gsl_odeiv2_driver_free(d);
    if (status != GSL_SUCCESS) return false;
    std::vector<double> c(m.canonical);
    m.to_canonical(t, y.data(), c.data());
    it = m.cached.emplace(t, std::move(c)).first;
  }
  std::copy(it->second.begin(), it->second.end(), canonical);
  return true;
}

}  // namespace cstab

// Checks shared by the tests of runtime-size models (methods/scalable.hpp):
// a model's closed-form derivatives against differences of its own rows.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "methods/scalable.hpp"

namespace cstab::testing {

// At (q, v): J from jacobian_pattern/jacobian against central differences
// of holonomic() (step 1e-5; every entry of the pattern once, inside the
// sizes), and gamma = v^T Phi'' v against the second difference of
// Phi(q + s v) (step s). `tol_j`, `tol_gamma`: absolute bounds; `what`
// names the case in failures.
inline void expect_derivatives_match_differences(const ScalableModel& model, const std::vector<double>& q,
                                                 const std::vector<double>& v, double s, double tol_j,
                                                 double tol_gamma, const std::string& what) {
  const int n = model.coords(), m = model.rows();
  const auto pattern = model.jacobian_pattern();
  std::vector<double> values(pattern.size()), gamma(static_cast<size_t>(m));
  model.jacobian(q.data(), values.data());
  model.gamma(q.data(), v.data(), gamma.data());
  // Dense J from the entries; every position at most once.
  std::vector<double> J(static_cast<size_t>(m * n), 0.0);
  std::vector<int> seen(static_cast<size_t>(m * n), 0);
  for (size_t k = 0; k < pattern.size(); ++k) {
    const auto [r, c] = pattern[k];
    ASSERT_TRUE(r >= 0 && r < m && c >= 0 && c < n) << what;
    EXPECT_EQ(seen[size_t(r * n + c)]++, 0) << what << ": entry (" << r << ", " << c << ") twice";
    J[size_t(r * n + c)] = values[k];
  }
  const double h = 1e-5;
  std::vector<double> qp = q, qm = q, fp(static_cast<size_t>(m)), fm(static_cast<size_t>(m)),
                      f0(static_cast<size_t>(m));
  for (int c = 0; c < n; ++c) {
    qp[size_t(c)] += h;
    qm[size_t(c)] -= h;
    model.holonomic(qp.data(), fp.data());
    model.holonomic(qm.data(), fm.data());
    qp[size_t(c)] = qm[size_t(c)] = q[size_t(c)];
    for (int r = 0; r < m; ++r)
      EXPECT_NEAR(J[size_t(r * n + c)], (fp[size_t(r)] - fm[size_t(r)]) / (2 * h), tol_j)
          << what << " " << r << " " << c;
  }
  model.holonomic(q.data(), f0.data());
  for (int j = 0; j < n; ++j) {
    qp[size_t(j)] = q[size_t(j)] + s * v[size_t(j)];
    qm[size_t(j)] = q[size_t(j)] - s * v[size_t(j)];
  }
  model.holonomic(qp.data(), fp.data());
  model.holonomic(qm.data(), fm.data());
  for (int r = 0; r < m; ++r)
    EXPECT_NEAR(gamma[size_t(r)], (fp[size_t(r)] - 2 * f0[size_t(r)] + fm[size_t(r)]) / (s * s), tol_gamma)
        << what << " " << r;
}

}  // namespace cstab::testing

namespace cstab::testing {

// How a runtime-size formulation's index-1 ODE y' = f(y) couples its states:
// the Jacobian by central differences at y (step 1e-6 times max(1, |y_j|)),
// an entry counted when it exceeds 1e-9 of the largest. `filled`: the share
// of nonzero entries in the acceleration rows (the lower half); `bandwidth`:
// the largest |i - j| of a nonzero entry anywhere, which a band linear
// solver would need as its half-bandwidth (2n - 1 means dense).
struct OdeCoupling {
  double filled = 0;
  int bandwidth = 0;
};
inline OdeCoupling ode_coupling(const ScalableModel& model, const ScalableSettings& settings,
                                const std::vector<double>& y) {
  const auto f = make_scalable_formulation(model, settings);
  const int N = static_cast<int>(y.size()), n = N / 2;
  std::vector<double> J(static_cast<size_t>(N) * static_cast<size_t>(N)), yp = y, ym = y, fp(static_cast<size_t>(N)),
                                                                          fm(static_cast<size_t>(N));
  double largest = 0;
  for (int j = 0; j < N; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(y[size_t(j)]));
    yp[size_t(j)] += h;
    ym[size_t(j)] -= h;
    EXPECT_TRUE(f->rhs(0, yp.data(), fp.data()) && f->rhs(0, ym.data(), fm.data()));
    yp[size_t(j)] = ym[size_t(j)] = y[size_t(j)];
    for (int i = 0; i < N; ++i) {
      const double d = (fp[size_t(i)] - fm[size_t(i)]) / (2 * h);
      J[size_t(i) * size_t(N) + size_t(j)] = d;
      largest = std::max(largest, std::abs(d));
    }
  }
  OdeCoupling out;
  long nonzero = 0;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      if (std::abs(J[size_t(i) * size_t(N) + size_t(j)]) <= 1e-9 * largest) continue;
      out.bandwidth = std::max(out.bandwidth, std::abs(i - j));
      if (i >= n) ++nonzero;
    }
  out.filled = static_cast<double>(nonzero) / (static_cast<double>(n) * N);
  return out;
}

}  // namespace cstab::testing

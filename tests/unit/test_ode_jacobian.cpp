// The index-1 methods' AD Jacobians (methods/ode_jacobian.hpp,
// OdeSystem::jacobian) against an independent formulation: Richardson-
// extrapolated central differences of the same right-hand side, on every
// problem, at the start and at a point off the constraint manifold (where
// the stabilization terms act). Then the integrators that take them:
// cvode-bdf, ark-dirk and msbdf with the system's Jacobian reach the same
// solution as with difference quotients (CSTAB_JACOBIAN=dq), and CVODE
// spends no right-hand side on its Jacobian.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "problems/registry.hpp"

namespace cstab {
namespace {

const std::vector<std::string> kMethods = {"none", "projection", "post-stabilization", "baumgarte", "penalty"};

struct Case {
  std::string problem, method, formulation;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.problem << " " << c.method << "@" << c.formulation; }

std::vector<Case> jacobian_cases() {
  std::vector<Case> out;
  for (const auto& p : all_problems()) {
    for (const auto& m : kMethods) {
      if (!p->why_not(m).empty()) continue;
      for (const auto& f : p->info().formulations) {
        try {
          p->method_params(m, f.name);
        } catch (const UsageError&) {
          continue;
        }
        out.push_back({p->info().name, m, f.name});
      }
    }
  }
  return out;
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string s = info.param.problem + "_" + info.param.method + "_" + info.param.formulation;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

// df/dy_j by central differences at steps h and h/2, extrapolated
// (error O(h^4)); false if the right-hand side fails.
bool difference_column(Formulation& form, double t, std::vector<double> y, int j, double h, std::vector<double>& col) {
  const int n = form.dimension();
  std::vector<double> fp(n), fm(n), d1(n), d2(n);
  const double y0 = y[j];
  for (int pass = 0; pass < 2; ++pass) {
    const double step = pass == 0 ? h : h / 2;
    y[j] = y0 + step;
    if (!form.rhs(t, y.data(), fp.data())) return false;
    y[j] = y0 - step;
    if (!form.rhs(t, y.data(), fm.data())) return false;
    auto& d = pass == 0 ? d1 : d2;
    for (int i = 0; i < n; ++i) d[i] = (fp[i] - fm[i]) / (2 * step);
  }
  col.resize(n);
  for (int i = 0; i < n; ++i) col[i] = (4 * d2[i] - d1[i]) / 3;
  return true;
}

class OdeJacobian : public ::testing::TestWithParam<Case> {};

TEST_P(OdeJacobian, MatchesDifferenceQuotients) {
  const Case& c = GetParam();
  const Problem& p = find_problem(c.problem);
  // penalty at alpha = 100, not its default 1e4: M + p A^T A's condition
  // grows with alpha, and the differences' round-off with it (at 1e4 they
  // scatter by 1e-3 relative between steps 1e-4 and 1e-5 on andrews while
  // the AD values do not move); the formula does not depend on alpha.
  std::vector<std::pair<std::string, std::string>> params;
  if (c.method == "penalty") params = {{"alpha", "100"}};
  auto form =
      p.make(c.method, c.formulation, Params::resolve(p.method_params(c.method, c.formulation), params, c.method));
  // Redundant rows (where baumgarte refuses): the multipliers are not
  // unique, the Schur-complement methods give no Jacobian, and the
  // integrators take difference quotients; penalty's has no multipliers to
  // choose and holds there too.
  const bool redundant = !p.why_not("baumgarte").empty();
  // The runtime-size path (methods/scalable.hpp) gives no Jacobian: the
  // implicit integrators take difference quotients there.
  if (p.why_not("generalized-alpha").find("runtime") != std::string::npos) {  // n-four-bar, fekete
    EXPECT_FALSE(form->has_jacobian());
    return;
  }
  if (redundant && c.method != "penalty") {
    EXPECT_FALSE(form->has_jacobian());
    return;
  }
  ASSERT_TRUE(form->has_jacobian());
  const int n = form->dimension();
  std::vector<double> y0(n);
  form->initial_state(y0.data());
  const double horizon = p.info().reference_time > 0 ? p.info().reference_time : 1.0;
  const double t = 0.1 * horizon;
  std::vector<double> off = y0;
  for (int i = 0; i < n; ++i) off[i] += 1e-3 * (1 + std::abs(y0[i])) * std::sin(1.0 + 2.3 * i);
  int checked = 0;
  for (const auto& y : {y0, off}) {
    std::vector<double> J(size_t(n) * n);
    const bool ok = form->jacobian(t, y.data(), J.data());
    ASSERT_TRUE(ok) << "no Jacobian at a full-rank point";
    double worst = 0;
    int worst_i = -1, worst_j = -1;
    std::vector<std::vector<double>> fd(n);
    for (int j = 0; j < n; ++j)
      ASSERT_TRUE(difference_column(*form, t, y, j, 1e-4 * (1 + std::abs(y[j])), fd[j])) << form->failure_reason();
    // Within 1e-5 relative to the entry, with floors for entries that
    // vanish: 2e-3 of the row's largest and of the whole matrix's (at
    // least 1, its identity block), i.e. an absolute 2e-8 of the matrix:
    // the differences' round-off on the biped is 1.3e-8 built by GCC 12 and
    // 2.1e-8 by clang 14 (entry (17, 8), where AD gives 6e-15).
    double scale = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) scale = std::max(scale, std::abs(fd[j][i]));
    for (int i = 0; i < n; ++i) {
      double row_scale = 0;
      for (int j = 0; j < n; ++j) row_scale = std::max(row_scale, std::abs(fd[j][i]));
      for (int j = 0; j < n; ++j) {
        const double err =
            std::abs(J[i + size_t(j) * n] - fd[j][i]) / (std::abs(fd[j][i]) + 2e-3 * row_scale + 2e-3 * scale);
        if (err > worst) worst = err, worst_i = i, worst_j = j;
      }
    }
    if (worst_i >= 0) {
      EXPECT_LT(worst, 1e-5) << "entry (" << worst_i << ", " << worst_j << "): AD " << J[worst_i + size_t(worst_j) * n]
                             << ", differences " << fd[worst_j][worst_i] << " (point "
                             << (checked == 0 ? "start" : "off") << ")";
    }
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

INSTANTIATE_TEST_SUITE_P(All, OdeJacobian, ::testing::ValuesIn(jacobian_cases()), case_name);

std::string extra(const RunResult& r, const std::string& name) {
  for (const auto& [k, v] : r.extra)
    if (k == name) return v;
  return "";
}

RunResult run_with(const std::string& problem, const std::string& method, const std::string& integrator, double tol,
                   bool dq) {
  if (dq)
    ::setenv("CSTAB_JACOBIAN", "dq", 1);
  else
    ::unsetenv("CSTAB_JACOBIAN");
  const Problem& p = find_problem(problem);
  RunConfig cfg;
  cfg.t_end = p.info().reference_time;  // and the reference there
  cfg.problem = problem;
  cfg.method = method;
  cfg.integrator = integrator;
  cfg.step.rtol = cfg.step.atol = tol;
  cfg.write_series = false;
  RunResult r = run_case(p, cfg, "");
  ::unsetenv("CSTAB_JACOBIAN");
  return r;
}

struct IntegratorCase {
  std::string problem, method, integrator;
};
void PrintTo(const IntegratorCase& c, std::ostream* os) { *os << c.problem << " " << c.method << " " << c.integrator; }

class SystemJacobian : public ::testing::TestWithParam<IntegratorCase> {};

// Same tolerance, same solution: the reference errors with the system's
// Jacobian and with difference quotients within a factor 3 of each other
// (the Newton iteration converges to the same tolerance either way).
TEST_P(SystemJacobian, SameSolutionAsDifferenceQuotients) {
  const IntegratorCase& c = GetParam();
  const RunResult ad = run_with(c.problem, c.method, c.integrator, 1e-8, false);
  const RunResult dq = run_with(c.problem, c.method, c.integrator, 1e-8, true);
  ASSERT_EQ(ad.status, "ok") << ad.reason;
  ASSERT_EQ(dq.status, "ok") << dq.reason;
  EXPECT_EQ(extra(ad, "jacobian"), "system");
  EXPECT_EQ(extra(dq, "jacobian"), "dq");
  ASSERT_TRUE(std::isfinite(ad.ref_error));
  EXPECT_LT(ad.ref_error, 3 * dq.ref_error + 1e-9);
  EXPECT_LT(dq.ref_error, 3 * ad.ref_error + 1e-9);
  if (c.integrator == "cvode-bdf") {
    EXPECT_EQ(extra(ad, "cvode_jac_rhs_evals"), "0");
    EXPECT_EQ(extra(ad, "jac_dq_points"), "0");
    EXPECT_NE(extra(dq, "cvode_jac_rhs_evals"), "0");
  }
  if (c.integrator == "msbdf") {
    EXPECT_NE(extra(ad, "msbdf_system_jacobians"), "0");
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, SystemJacobian,
                         ::testing::Values(IntegratorCase{"slider-crank", "baumgarte", "cvode-bdf"},
                                           IntegratorCase{"andrews", "penalty", "cvode-bdf"},
                                           IntegratorCase{"wheel", "projection", "cvode-projection"},
                                           IntegratorCase{"car-axis", "baumgarte", "ark-dirk-ark548"},
                                           IntegratorCase{"ball", "none", "msbdf"}),
                         [](const ::testing::TestParamInfo<IntegratorCase>& info) {
                           std::string s = info.param.problem + "_" + info.param.method + "_" + info.param.integrator;
                           for (char& ch : s)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return s;
                         });

}  // namespace
}  // namespace cstab

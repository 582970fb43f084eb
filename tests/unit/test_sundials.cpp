// The SUNDIALS ODE integrators (cvode-bdf, cvode-adams, ark-erk-*, ark-dirk-*)
// against closed-form solutions, a stiff ordering against GSL rk8pd, the
// restart path the projection methods take, and their command-line errors;
// post-stabilization against projection on the slider crank.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/params.hpp"
#include "harness/integrator.hpp"
#include "harness/run.hpp"
#include "methods/post_stabilization.hpp"
#include "problems/registry.hpp"
#include "problems/slider_crank/slider_crank.hpp"
#include "tests/support/test_util.hpp"

namespace cstab {
namespace {

// x' = v, v' = -w^2 x, y' = -y + sin t: linear, with the closed form
//   x = cos(w t) + 0.3 sin(w t) / w,  y = (y0 + 1/2) e^-t + (sin t - cos t) / 2.
class LinearSystem final : public OdeSystem {
 public:
  static constexpr double kW = 2.0, kY0 = 0.7;
  int dimension() const override { return 3; }
  bool rhs(double t, const double* y, double* d) override {
    d[0] = y[1];
    d[1] = -kW * kW * y[0];
    d[2] = -y[2] + std::sin(t);
    return true;
  }
  static std::array<double, 3> initial() { return {1.0, 0.3, kY0}; }
  static std::array<double, 3> exact(double t) {
    return {std::cos(kW * t) + 0.3 / kW * std::sin(kW * t), -kW * std::sin(kW * t) + 0.3 * std::cos(kW * t),
            (kY0 + 0.5) * std::exp(-t) + 0.5 * (std::sin(t) - std::cos(t))};
  }
};

double max_error(const double* y, double t) {
  const auto ex = LinearSystem::exact(t);
  double e = 0;
  for (int i = 0; i < 3; ++i) e = std::max(e, std::abs(y[i] - ex[i]));
  return e;
}

struct Outcome {
  std::vector<double> y;
  long steps = 0, rhs = 0;
};

Outcome integrate(OdeSystem& sys, const std::string& name, double tol, double t_end, const double* y0) {
  auto integ = make_integrator(name, StepSettings{0, tol, tol});
  integ->start(sys, 0.0, y0);
  while (integ->t() < t_end) {
    const StepOutcome o = integ->step(t_end);
    EXPECT_EQ(o, StepOutcome::kOk) << name << ": " << integ->failure_reason();
    if (o != StepOutcome::kOk) break;
  }
  EXPECT_EQ(integ->t(), t_end) << name << " lands exactly on the limit";
  Outcome out;
  out.y.assign(integ->y(), integ->y() + sys.dimension());
  out.steps = integ->steps();
  out.rhs = integ->rhs_evals();
  return out;
}

const std::vector<std::string> kSundialsOde = {"cvode-bdf",       "cvode-adams",     "ark-erk-dp5",
                                               "ark-erk-verner6", "ark-erk-fehlberg8", "ark-dirk-ark548",
                                               "ark-dirk-sdirk534"};

class SundialsOde : public ::testing::TestWithParam<std::string> {};

// Global error against the closed form: falls as the tolerance falls, and
// is small at the tightest one.
TEST_P(SundialsOde, ErrorFallsWithToleranceToTheClosedForm) {
  const std::string name = GetParam();
  const auto y0 = LinearSystem::initial();
  std::vector<double> errors;
  std::vector<long> steps;
  for (double tol : {1e-4, 1e-6, 1e-8, 1e-10}) {
    LinearSystem sys;
    const Outcome o = integrate(sys, name, tol, 3.0, y0.data());
    errors.push_back(max_error(o.y.data(), 3.0));
    steps.push_back(o.steps);
  }
  for (size_t k = 0; k + 1 < errors.size(); ++k) {
    EXPECT_LT(errors[k + 1], errors[k]) << name << ": tolerance step " << k;
    EXPECT_GT(steps[k + 1], steps[k]) << name << ": tolerance step " << k;
  }
  EXPECT_LT(errors.back(), 1e-7) << name << " at rtol = atol = 1e-10";
  EXPECT_LT(errors.front(), 1e-2) << name << " at rtol = atol = 1e-4";
}

// A restart after every step (what a post-step projection triggers, here
// with y unchanged) keeps the counts running and the solution accurate.
TEST_P(SundialsOde, RestartsCarryTheCountersAndKeepAccuracy) {
  const std::string name = GetParam();
  LinearSystem sys;
  const auto y0 = LinearSystem::initial();
  auto integ = make_integrator(name, StepSettings{0, 1e-8, 1e-8});
  integ->start(sys, 0.0, y0.data());
  long taken = 0;
  while (integ->t() < 1.0) {
    ASSERT_EQ(integ->step(1.0), StepOutcome::kOk) << integ->failure_reason();
    ++taken;
    ASSERT_EQ(integ->steps(), taken);
    ASSERT_TRUE(integ->notify_modified()) << integ->failure_reason();
    ASSERT_EQ(integ->steps(), taken);
  }
  // ARKODE's one-step schemes lose nothing by a reset. CVODE restarts at
  // order 1 with its initial-step estimate: every step is a first step,
  // which costs accuracy (measured 2.2e-4 here at rtol = atol = 1e-8, both
  // cvode-bdf and cvode-adams) and steps (docs/methods.md).
  EXPECT_LT(max_error(integ->y(), 1.0), name.rfind("cvode", 0) == 0 ? 1e-3 : 1e-5);
  // The solver's own step counter column equals steps(), restarts included.
  bool found = false;
  for (const auto& [key, value] : integ->statistics()) {
    if (key == "cvode_steps" || key == "ark_steps") {
      EXPECT_EQ(std::stol(value), taken) << key;
      found = true;
    }
    if (key == "cvode_restarts" || key == "ark_restarts") {
      EXPECT_EQ(std::stol(value), taken) << key;
    }
  }
  EXPECT_TRUE(found);
  EXPECT_GE(integ->rhs_evals(), taken);
}

INSTANTIATE_TEST_SUITE_P(All, SundialsOde, ::testing::ValuesIn(kSundialsOde), [](const auto& info) {
  std::string s = info.param;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
});

// Higher order, fewer steps at a tight tolerance: Fehlberg 8(7) against
// Dormand-Prince 5(4). (Verner 6(5) is not between them: it took 638 steps
// to Dormand-Prince's 202 here, measured; docs/methods.md.)
TEST(ArkErk, EighthOrderTableTakesFewerStepsThanFifth) {
  const auto y0 = LinearSystem::initial();
  LinearSystem a, b;
  const long dp5 = integrate(a, "ark-erk-dp5", 1e-10, 3.0, y0.data()).steps;
  const long f8 = integrate(b, "ark-erk-fehlberg8", 1e-10, 3.0, y0.data()).steps;
  EXPECT_LT(2 * f8, dp5) << "fehlberg8 " << f8 << ", dp5 " << dp5;
}

// Stiff linear system: y1' = -k (y1 - cos t) - sin t (y1 = cos t + (y1(0) - 1) e^-kt),
// y2' = -y2 + y1. An explicit scheme is held to h ~ 1/k by stability, BDF is not.
class StiffSystem final : public OdeSystem {
 public:
  static constexpr double kK = 1e5;
  int dimension() const override { return 2; }
  bool rhs(double t, const double* y, double* d) override {
    d[0] = -kK * (y[0] - std::cos(t)) - std::sin(t);
    d[1] = -y[1] + y[0];
    return true;
  }
};

TEST(CvodeBdf, StiffSystemTakesFarFewerStepsThanRk8pd) {
  const std::array<double, 2> y0 = {2.0, 0.0};
  StiffSystem a, b;
  const Outcome bdf = integrate(a, "cvode-bdf", 1e-6, 2.0, y0.data());
  const Outcome rk = integrate(b, "rk8pd", 1e-6, 2.0, y0.data());
  EXPECT_NEAR(bdf.y[0], std::cos(2.0), 1e-5);
  EXPECT_NEAR(rk.y[0], std::cos(2.0), 1e-5);
  EXPECT_LT(bdf.steps * 20, rk.steps) << "cvode-bdf " << bdf.steps << " steps, rk8pd " << rk.steps;
  EXPECT_LT(bdf.rhs * 20, rk.rhs) << "cvode-bdf " << bdf.rhs << " rhs, rk8pd " << rk.rhs;
  StiffSystem c;
  const Outcome dirk = integrate(c, "ark-dirk-ark548", 1e-6, 2.0, y0.data());
  EXPECT_NEAR(dirk.y[0], std::cos(2.0), 1e-5);
  EXPECT_LT(dirk.steps * 20, rk.steps) << "ark-dirk-ark548 " << dirk.steps << " steps, rk8pd " << rk.steps;
}

// CVODE's dense output (CVodeGetDky) inside the last step.
TEST(Cvode, DenseOutputInsideTheLastStep) {
  for (const char* name : {"cvode-bdf", "cvode-adams"}) {
    LinearSystem sys;
    const auto y0 = LinearSystem::initial();
    auto integ = make_integrator(name, StepSettings{0, 1e-10, 1e-10});
    integ->start(sys, 0.0, y0.data());
    for (int i = 0; i < 30; ++i) ASSERT_EQ(integ->step(5.0), StepOutcome::kOk);
    const double h = integ->last_step_size();
    ASSERT_GT(h, 0);
    std::array<double, 3> mid{};
    ASSERT_TRUE(integ->state_at(integ->t() - 0.5 * h, mid.data())) << name;
    EXPECT_LT(max_error(mid.data(), integ->t() - 0.5 * h), 1e-7) << name;
    EXPECT_FALSE(integ->state_at(integ->t() + h, mid.data())) << name << ": no extrapolation";
  }
}

// The command line: a Butcher table that does not exist, or no table, is a
// usage error naming the valid ones; so is a non-positive tolerance.
int run_cli(const std::string& args, std::string* err) {
  const auto dir = std::filesystem::temp_directory_path() / ("cstab_sundials_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string err_file = (dir / "err.txt").string();
  const std::string cmd = testing::quote(CSTAB_BINARY) + " " + args + " --out " + testing::quote((dir / "R").string()) +
                          " >/dev/null 2>" + testing::quote(err_file);
  const int code = testing::exit_code(std::system(cmd.c_str()));
  *err = testing::slurp(err_file);
  EXPECT_FALSE(std::filesystem::exists(dir / "R" / "summary.csv")) << args;
  std::filesystem::remove_all(dir);
  return code;
}

TEST(SundialsCli, UnknownButcherTableAndBadToleranceExitTwo) {
  const std::string base = "run --problem slider-crank --method projection --t-end 0.1 ";
  std::string err;
  EXPECT_EQ(run_cli(base + "--integrator ark-erk-verner9 --rtol 1e-8 --atol 1e-8", &err), 2);
  EXPECT_NE(err.find("unknown Butcher table 'verner9'"), std::string::npos) << err;
  for (const char* valid : {"ark-erk-dp5", "ark-erk-verner6", "ark-erk-fehlberg8"})
    EXPECT_NE(err.find(valid), std::string::npos) << err;
  EXPECT_EQ(run_cli(base + "--integrator ark-erk --rtol 1e-8 --atol 1e-8", &err), 2);
  EXPECT_NE(err.find("names no Butcher table"), std::string::npos) << err;
  EXPECT_EQ(run_cli(base + "--integrator ark-dirk-nope --rtol 1e-8 --atol 1e-8", &err), 2);
  EXPECT_NE(err.find("ark-dirk-ark548"), std::string::npos) << err;
  for (const char* integ : {"cvode-bdf", "cvode-adams", "ark-erk-fehlberg8", "ark-dirk-ark548"}) {
    EXPECT_EQ(run_cli(base + "--integrator " + integ + " --rtol 0 --atol 1e-8", &err), 2) << integ;
    EXPECT_NE(err.find("--rtol"), std::string::npos) << err;
    EXPECT_EQ(run_cli(base + "--integrator " + integ + " --rtol 1e-8 --atol -1", &err), 2) << integ;
    EXPECT_NE(err.find("--atol"), std::string::npos) << err;
  }
}

// ---- post-stabilization ----

// The slider crank's model, counting mass-matrix evaluations in double (each
// one is followed by a Cholesky factorization in the methods below).
struct CountingSliderCrank : SliderCrankMechanical {
  using SliderCrankMechanical::SliderCrankMechanical;
  inline static long mass_calls = 0;
  template <class S>
  void mass(const S& t, const Vec<S, 3>& q, Eigen::Matrix<S, 3, 3>& M) const {
    if constexpr (std::is_same_v<S, double>) ++mass_calls;
    SliderCrankMechanical::mass(t, q, M);
  }
};

struct Measured {
  double max_residual = 0;
  long post_step_factorizations = 0;
  long rhs = 0;
};

Measured drive(Formulation& form, const std::string& integrator, const StepSettings& s, double t_end) {
  auto integ = make_integrator(integrator, s);
  std::vector<double> y(form.dimension()), r(form.constraints().size());
  form.initial_state(y.data());
  integ->start(form, 0.0, y.data());
  Measured m;
  while (integ->t() < t_end) {
    const StepOutcome o = integ->step(t_end);
    if (o == StepOutcome::kPastLimit) break;
    EXPECT_EQ(o, StepOutcome::kOk) << integ->failure_reason();
    if (o != StepOutcome::kOk) break;
    const long before = CountingSliderCrank::mass_calls;
    if (form.post_step(integ->t(), integ->y())) {
      EXPECT_TRUE(integ->notify_modified());
    }
    m.post_step_factorizations += CountingSliderCrank::mass_calls - before;
    form.residuals(integ->t(), integ->y(), r.data());
    for (double x : r) m.max_residual = std::max(m.max_residual, std::abs(x));
  }
  m.rhs = integ->rhs_evals();
  return m;
}

TEST(PostStabilization, ResidualsInProjectionsClassAtLowerCost) {
  const CountingSliderCrank model{SliderCrankParameters{}};
  for (const auto& [integrator, s] : {std::pair{std::string("rk4"), StepSettings{1e-2, 0, 0}},
                                      std::pair{std::string("rk8pd"), StepSettings{0, 1e-6, 1e-6}}}) {
    IndexOneFormulation<CountingSliderCrank> none(model, false, 0, 0), projection(model, true, 1e-13, 5);
    PostStabilizationFormulation<CountingSliderCrank> post(model, false), post_refactor(model, true);
    const Measured n = drive(none, integrator, s, 10.0);
    const Measured p = drive(projection, integrator, s, 10.0);
    const Measured ps = drive(post, integrator, s, 10.0);
    const Measured pr = drive(post_refactor, integrator, s, 10.0);
    std::printf("%s: max residual none %.3g projection %.3g post %.3g post-refactor %.3g; post-step factorizations "
                "projection %ld post %ld post-refactor %ld; rhs %ld %ld %ld\n",
                integrator.c_str(), n.max_residual, p.max_residual, ps.max_residual, pr.max_residual,
                p.post_step_factorizations, ps.post_step_factorizations, pr.post_step_factorizations, p.rhs, ps.rhs,
                pr.rhs);
    // Far below the unstabilized drift, and at projection's level (one
    // correction of a drift of the size of the local error).
    EXPECT_LT(ps.max_residual * 1e3, n.max_residual) << integrator;
    EXPECT_LT(pr.max_residual * 1e3, n.max_residual) << integrator;
    EXPECT_LE(ps.max_residual, std::max(10 * p.max_residual, 1e-12)) << integrator << " projection " << p.max_residual;
    EXPECT_LE(pr.max_residual, std::max(10 * p.max_residual, 1e-12)) << integrator << " projection " << p.max_residual;
    // Cheaper: one factorization per step (two with refactor = 1) against
    // projection's two, and no more right-hand sides.
    EXPECT_LT(ps.post_step_factorizations, p.post_step_factorizations) << integrator;
    EXPECT_LE(pr.post_step_factorizations, p.post_step_factorizations) << integrator;
    EXPECT_LE(ps.rhs, p.rhs + p.rhs / 10) << integrator;
  }
}

TEST(PostStabilization, RefactorIsZeroOrOne) {
  const Problem& p = find_problem("slider-crank");
  const auto specs = p.method_params("post-stabilization", "");
  EXPECT_THROW(p.make("post-stabilization", "", Params::resolve(specs, {{"refactor", "0.5"}}, "post-stabilization")),
               UsageError);
  EXPECT_NO_THROW(p.make("post-stabilization", "", Params::resolve(specs, {{"refactor", "1"}}, "post-stabilization")));
}

}  // namespace
}  // namespace cstab

namespace cstab {
namespace {

// cvode-projection: the method's projection inside CVODE (CVodeSetProjFn)
// keeps BDF's history, where the harness's post-step projection restarts
// CVODE at order 1 after every step (ordering: far fewer steps, a smaller
// error; the residual stays at projection's level).
TEST(CvodeProjection, KeepsTheHistoryWhereARestartLosesIt) {
  const Problem& p = find_problem("slider-crank");
  auto run = [&](const std::string& integrator, const std::string& method) {
    RunConfig cfg;
    cfg.problem = "slider-crank";
    cfg.method = method;
    cfg.integrator = integrator;
    cfg.step.rtol = cfg.step.atol = 1e-8;
    cfg.t_end = 1.0;
    cfg.ref_time = 1.0;
    cfg.write_series = false;
    return run_case(p, cfg, "");
  };
  for (const char* method : {"projection", "post-stabilization"}) {
    const RunResult restart = run("cvode-bdf", method);
    const RunResult inside = run("cvode-projection", method);
    const RunResult inside_noerr = run("cvode-projection-noerr", method);
    for (const RunResult* r : {&restart, &inside, &inside_noerr}) {
      ASSERT_EQ(r->status, "ok") << r->integrator << " " << method << ": " << r->reason;
      EXPECT_LT(r->max_residual, 1e-12) << r->integrator << " " << method;
    }
    EXPECT_LT(inside.steps * 20, restart.steps) << method;
    EXPECT_LT(inside_noerr.steps * 20, restart.steps) << method;
    EXPECT_LT(inside.ref_error, restart.ref_error) << method;
    bool counted = false;
    for (const auto& [key, value] : inside.extra)
      if (key == "cvode_projections") counted = std::stol(value) >= inside.steps;
    EXPECT_TRUE(counted) << "cvode_projections >= steps";
  }
}

}  // namespace
}  // namespace cstab

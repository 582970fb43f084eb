// No heap allocation per step. This binary counts heap allocations (with
// glibc, the whole malloc family: harness/alloc_count.hpp, the counter
// `cstab check` uses); a counter
// armed around a window of steps must stay at zero:
//  * StepLoop: every problem x method (ODE and DAE) x integrator, stepping
//    the integrator directly (with the method's post-step hook), after a
//    warm-up;
//  * Harness: run_case without a series file (the observation path of every
//    step: residuals, energy, first integrals, divergence checks) allocates
//    the same number of times over N and over 4N steps, so nothing per step.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <gsl/gsl_vector.h>

#include <algorithm>
#include <cstdlib>

#include <ostream>
#include <string>
#include <vector>

#include "harness/alloc_count.hpp"
#include "harness/integrator.hpp"
#include "harness/run.hpp"
#include "methods/pair.hpp"
#include "problems/registry.hpp"
#include "tests/support/escape.hpp"

namespace cstab {
namespace {

using testing::escape;

TEST(AllocationCounter, CountsAllocations) {
  // The counter itself must see an allocation, or every zero below is vacuous.
  long seen = 0;
  {
    AllocationWindow w;
    auto* v = new std::vector<double>(100);
    escape(v);
    escape(v->data());
    seen = w.count();
    delete v;
  }
  EXPECT_EQ(seen, 2);  // the vector object and its buffer
}

// Beyond operator new: Eigen's dynamic storage (std::malloc through
// Eigen::internal::aligned_malloc) and a C library's malloc/calloc/realloc
// and aligned allocations, which the operator-new counter never saw.
TEST(AllocationCounter, SeesMallocFamily) {
  if (!AllocationWindow::counts_malloc_family()) GTEST_SKIP() << "AddressSanitizer owns malloc: operator new only";
  long eigen = 0, c_family = 0;
  {
    AllocationWindow w;
    Eigen::VectorXd v(64);
    v.setOnes();
    eigen = w.count();
    ::testing::Test::RecordProperty("sum", std::to_string(v.sum()));
  }
  {
    // Each pointer escapes through a volatile store, or the compiler may
    // drop a malloc/free pair whose memory is never used.
    void* volatile sink[5] = {};
    AllocationWindow w;
    sink[0] = std::malloc(32);
    sink[1] = std::calloc(4, 8);
    sink[0] = std::realloc(sink[0], 4096);
    sink[2] = std::aligned_alloc(64, 128);
    void* d = nullptr;
    const int rc = posix_memalign(&d, 64, 128);
    sink[3] = d;
    c_family = w.count();
    EXPECT_EQ(rc, 0);
    for (void* p : sink) std::free(p);
  }
  EXPECT_EQ(eigen, 1);
  EXPECT_EQ(c_family, 5);
}

// The return-address test that tells GSL's own allocations from cstab's:
// a GSL vector allocated here is GSL's (gsl_vector_alloc calls malloc), an
// Eigen vector is not.
TEST(AllocationCounter, TellsLibraryAllocationsApart) {
  if (!AllocationWindow::counts_malloc_family()) GTEST_SKIP() << "AddressSanitizer owns malloc: operator new only";
  long own = 0, library = 0;
  {
    AllocationWindow w;
    gsl_vector* g = gsl_vector_alloc(16);
    Eigen::VectorXd v(16);
    v.setZero();
    escape(v.data());
    gsl_vector_set_zero(g);
    own = w.count();
    library = w.library_count();
    gsl_vector_free(g);
  }
  EXPECT_EQ(own, 1);      // Eigen's storage
  EXPECT_EQ(library, 3);  // the vector, its block and the block's data
}

// A system that allocates in its right-hand side: the counter must see it
// through the integrator (4 right-hand sides per RK4 step).
class AllocatingSystem final : public OdeSystem {
 public:
  int dimension() const override { return 2; }
  bool rhs(double, const double* y, double* dydt) override {
    scratch_ = std::vector<double>(y, y + 2);  // escapes into a member: cannot be elided
    dydt[0] = scratch_[1];
    dydt[1] = -scratch_[0];
    return true;
  }

 private:
  std::vector<double> scratch_;
};

TEST(AllocationCounter, SeesAllocationsInsideSteps) {
  AllocatingSystem sys;
  auto integ = make_integrator("rk4", StepSettings{1e-2, 0, 0});
  const double y0[2] = {1, 0};
  integ->start(sys, 0.0, y0);
  long allocations = 0;
  {
    AllocationWindow w;
    for (int i = 0; i < 10; ++i) integ->step(1e300);
    allocations = w.count();
  }
  EXPECT_EQ(allocations, 40);
}

struct Case {
  std::string problem, method, formulation, integrator;
};
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.problem << " " << c.method << "@" << c.formulation << " " << c.integrator;
}

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (const auto& p : all_problems()) {
    for (const auto& m : all_methods()) {
      if (!p->why_not(m.name).empty()) continue;
      for (const auto& f : p->info().formulations) {
        try {
          p->method_params(m.name, f.name);
        } catch (const UsageError&) {
          continue;  // the method does not run on this formulation
        }
        for (const auto& integ : all_integrators()) {
          if (m.kind != integ.kind) continue;
          out.push_back({p->info().name, m.name, f.name, integ.name});
        }
      }
    }
  }
  return out;
}

StepSettings settings_for(const Problem& p, const IntegratorInfo& info) {
  StepSettings s;
  const double horizon = p.info().reference_time > 0 ? p.info().reference_time : 1.0;
  // 1/20000 of the horizon: wheel-sharp's minimal ODE (1 - r kappa = 0.03 near
  // the sharp point) diverges with adams at 1/5000 of it.
  // At most a quarter of the problem's resolution step: the flyball
  // governor's fast damper mode (8e3 1/s) leaves Euler, Adams PECE and RATTLE's
  // fixed-point half-kick unstable at its resolution step itself.
  if (info.fixed_step) s.step = horizon / 20000;
  if (info.fixed_step && p.info().resolution_step > 0) s.step = std::min(s.step, p.info().resolution_step / 4);
  else s.rtol = s.atol = 1e-8;
  return s;
}

std::vector<std::pair<std::string, std::string>> params_for(const Case& c, const StepSettings& s) {
  // braun-goldfarb's default dt = the fixed step does not exist for adaptive schemes.
  if (c.method == "braun-goldfarb") return {{"dt", "1e-2"}};
  // h * lambda = 0.5 at every step, inside the explicit schemes' stability
  // intervals whatever the step.
  if (c.method == "pesterev") return {{"lambda", std::to_string(s.step > 0 ? 0.5 / s.step : 50.0)}};
  return {};
}

class StepLoop : public ::testing::TestWithParam<Case> {};

TEST_P(StepLoop, NoAllocationPerStep) {
  const Case& c = GetParam();
  const Problem& p = find_problem(c.problem);
  const auto specs = p.method_params(c.method, c.formulation);
  const IntegratorInfo& info = find_integrator(c.integrator);
  const StepSettings s = settings_for(p, info);
  auto form = p.make(c.method, c.formulation, Params::resolve(specs, params_for(c, s), c.method));
  constexpr int kWarmup = 20, kSteps = 200;
  const StepAllocations a = count_step_allocations(*form, c.integrator, s, kWarmup, kSteps);
  ASSERT_FALSE(a.warmup_failed) << a.failure;
  ASSERT_EQ(a.taken, kSteps) << "step failed: " << a.failure;
  EXPECT_EQ(a.allocations, 0) << a.allocations << " allocations in " << kSteps << " steps";
  // What the libraries allocate themselves, bounded exactly where they say
  // how often they do it:
  //  * SUNDIALS' dense difference-quotient Jacobians (CVODE's, ARKODE's,
  //    IDA's *LsDenseDQJac) wrap each column in an N_Vector made by
  //    N_VCloneEmpty and freed at the end: 3 blocks per Jacobian, nothing else;
  //    with the system's own Jacobian (the index-1 methods' AD, passed by
  //    CVodeSetJacFn / ARKStepSetJacFn) SUNDIALS allocates nothing, nor with
  //    IDA's band matrix (idaLsBandDQJac perturbs preallocated vectors: the
  //    runtime-size ida-ggl, DaeSystem::half_bandwidth >= 0);
  //  * GSL 2.7's gsl_linalg_LU_decomp allocates its pivot vector (3 blocks)
  //    on each factorization of msbdf's iteration matrix; GSL does not count
  //    those, so the bound is 3 per factorization, at most 4 per step;
  //  * every other integrator: none.
  // (Under AddressSanitizer only operator new is counted: nothing from C.)
  const bool sundials_implicit = a.jacobian_evaluations >= 0;
  if (!AllocationWindow::counts_malloc_family()) {
    EXPECT_EQ(a.library_allocations, 0);
  } else if (sundials_implicit) {
    const auto* dae = dynamic_cast<const DaeSystem*>(form.get());
    const bool band = dae && dae->half_bandwidth() >= 0;
    EXPECT_EQ(a.library_allocations, a.system_jacobian || band ? 0 : 3 * a.jacobian_evaluations)
        << a.jacobian_evaluations << " Jacobian evaluations in " << kSteps << " steps";
  } else if (c.integrator == "msbdf") {
    EXPECT_EQ(a.library_allocations % 3, 0) << a.library_allocations;
    EXPECT_LE(a.library_allocations, 4 * 3 * kSteps);
  } else {
    EXPECT_EQ(a.library_allocations, 0) << "in " << c.integrator;
  }
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string s = info.param.problem + "_" + info.param.method + "_" + info.param.formulation + "_" +
                  info.param.integrator;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(All, StepLoop, ::testing::ValuesIn(all_cases()), case_name);

// The whole harness loop, observation included (no series file): the
// allocation count of a run must not depend on how many steps it takes.
// The runtime-size path at the issue's largest size (N = 320), where the
// registered problems above run at their default N: no allocation per step
// either, for every method on it (IDA's band matrix for ida-ggl).
TEST(RuntimeSize, NoAllocationPerStepAtN320) {
  for (const std::string name : {"n-four-bar", "fekete"}) {
    const auto problem = problem_variant(find_problem(name), {{"N", "320"}});
    for (const std::string method : {"none", "baumgarte", "projection", "post-stabilization", "ida-ggl"}) {
      const bool dae = method == "ida-ggl";
      if (dae && name == "fekete") continue;  // dense there: the registered N covers it
      auto form = problem->make(method, "", Params::resolve(problem->method_params(method, ""), {}, method));
      const StepSettings s = dae ? StepSettings{0, 1e-6, 1e-6} : StepSettings{1e-3, 0, 0};
      const StepAllocations a = count_step_allocations(*form, dae ? "ida" : "rk4", s, 5, 20);
      ASSERT_FALSE(a.warmup_failed) << name << " " << method << ": " << a.failure;
      ASSERT_EQ(a.taken, 20) << name << " " << method << ": " << a.failure;
      EXPECT_EQ(a.allocations, 0) << name << " " << method;
      if (AllocationWindow::counts_malloc_family()) {
        EXPECT_EQ(a.library_allocations, 0) << name << " " << method;
      }
    }
  }
}

class Harness : public ::testing::TestWithParam<Case> {};

TEST_P(Harness, AllocationsIndependentOfStepCount) {
  const Case& c = GetParam();
  const Problem& p = find_problem(c.problem);
  const IntegratorInfo& info = find_integrator(c.integrator);
  const double horizon = p.info().reference_time > 0 ? p.info().reference_time : 1.0;
  auto run = [&](double t_end, long* steps) {
    RunConfig cfg;
    cfg.problem = c.problem;
    cfg.method = c.method;
    cfg.formulation = c.formulation;
    cfg.integrator = c.integrator;
    cfg.step = settings_for(p, info);
    cfg.params = params_for(c, cfg.step);
    cfg.t_end = t_end;
    cfg.ref_time = 0;
    cfg.write_series = false;
    long allocations = 0;
    RunResult r;
    {
      AllocationWindow w;
      r = run_case(p, cfg, "");
      allocations = w.count();
    }
    EXPECT_EQ(r.status, "ok") << r.reason;
    *steps = r.steps;
    return allocations;
  };
  long steps_short = 0, steps_long = 0;
  const long short_run = run(horizon / 40, &steps_short);
  const long long_run = run(horizon / 10, &steps_long);
  ASSERT_GT(steps_long, steps_short);
  EXPECT_EQ(long_run, short_run) << steps_long - steps_short << " more steps made "
                                 << long_run - short_run << " more allocations";
}

// One integrator of each kind per problem x method keeps this cheap.
std::vector<Case> harness_cases() {
  std::vector<Case> out;
  for (const auto& c : all_cases())
    // (projection restarts msbdf after every step, with a new Jacobian:
    // seconds per run; StepLoop covers that pair.)
    // (Likewise CVODE, restarted at order 1 after every projection step.)
    if (c.integrator == "adams" || c.integrator == "rk8pd" || c.integrator == "ida" || c.integrator == "own" ||
        c.integrator == "ark-erk-dp5" ||
        ((c.integrator == "msbdf" || c.integrator == "cvode-bdf") && c.method != "projection" &&
         c.method != "post-stabilization"))
      out.push_back(c);
  return out;
}

INSTANTIATE_TEST_SUITE_P(All, Harness, ::testing::ValuesIn(harness_cases()), case_name);

}  // namespace
}  // namespace cstab

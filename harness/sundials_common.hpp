// What the SUNDIALS integrators share (ida_integrator.cpp,
// cvode_integrator.cpp, arkode_integrator.cpp): the context and the solver
// memory's lifetime, the state vector wrapping y(), a dense direct linear
// solver, the one-internal-step loop with a stop time at t_limit, restarts
// after a post-step hook changed y(), the callbacks' failure bookkeeping,
// and failures in words. A wrapper supplies the package's calls (the
// virtual hooks below) and its own set-up.
//
// Included only by those three files and sundials_common.cpp: it pulls in
// SUNDIALS' generic headers, not a package's.
#pragma once

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>
#include <sundials/sundials_nvector.h>

#include <array>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "harness/integrator.hpp"

namespace cstab {

static_assert(std::is_same_v<realtype, double>, "SUNDIALS must be built in double precision");

enum class SundialsPackage { kCvode, kArkode, kIda };
// A package's return code in words, or the package's name for it.
std::string sundials_flag_words(SundialsPackage package, int flag);

// An N_Vector, destroyed with its owner or when replaced.
class SundialsVector {
 public:
  SundialsVector() = default;
  ~SundialsVector() { reset(); }
  SundialsVector(const SundialsVector&) = delete;
  SundialsVector& operator=(const SundialsVector&) = delete;
  void reset(N_Vector v = nullptr) {
    if (v_) N_VDestroy(v_);
    v_ = v;
  }
  operator N_Vector() const { return v_; }

 private:
  N_Vector v_ = nullptr;
};

// A package's counter query on the solver memory: CVodeGetNumSteps, ...
using SundialsCounter = int (*)(void* mem, long* count);

// A solver's counters summed over restarts: a restart (CVodeReInit,
// ARKStepReset) resets the package's own, the totals carry them on.
template <std::size_t N>
class CarriedCounts {
 public:
  using Counts = std::array<long, N>;
  // `lazy`: counters a restart does not reset itself; the package resets
  // them at the first solve after it (CVODE's linear-solver counters, zeroed
  // by cvLsInitialize, not by CVodeReInit). Until that solve they still hold
  // what was carried, so they read as 0.
  explicit CarriedCounts(const std::array<const char*, N>& names, const std::array<bool, N>& lazy = {})
      : names_(names), lazy_(lazy) {}
  // The package's counters since its last (re)start, by the queries `get`
  // (0 where a query is null or there is no solver memory).
  static Counts read(void* mem, const std::array<SundialsCounter, N>& get) {
    Counts c{};
    for (std::size_t i = 0; i < N; ++i)
      if (mem && get[i]) get[i](mem, &c[i]);
    return c;
  }
  void clear() {
    carried_.fill(0);
    restarts_ = 0;
    pending_ = false;
  }
  Counts totals(Counts raw) const {
    for (std::size_t i = 0; i < N; ++i) raw[i] = (pending_ && lazy_[i] ? 0 : raw[i]) + carried_[i];
    return raw;
  }
  // Before a restart: keep what the package counted so far.
  void before_restart(const Counts& raw) {
    for (std::size_t i = 0; i < N; ++i)
      if (!(pending_ && lazy_[i])) carried_[i] += raw[i];
    ++restarts_;
  }
  // After it: whatever the restart left in the counters is counted again
  // from there on (zero if it reset them); the lazy ones wait for a solve.
  void after_restart(const Counts& raw) {
    for (std::size_t i = 0; i < N; ++i)
      if (!lazy_[i]) carried_[i] -= raw[i];
    pending_ = true;
  }
  // After each solve: the lazy counters have been reset and count again.
  void solved() { pending_ = false; }
  long restarts() const { return restarts_; }
  // The first `count` totals as summary columns (name, value).
  void append(std::vector<std::pair<std::string, std::string>>& out, const Counts& raw, std::size_t count = N) const {
    const Counts c = totals(raw);
    for (std::size_t i = 0; i < count; ++i) out.emplace_back(names_[i], std::to_string(c[i]));
  }

 private:
  std::array<const char*, N> names_;
  std::array<bool, N> lazy_;
  Counts carried_{};
  long restarts_ = 0;
  bool pending_ = false;  // restarted, and no solve since
};

class SundialsIntegrator : public Integrator {
 public:
  // How a wrapper names itself and the package's calls in failure reasons.
  struct Names {
    const char* tag;       // "cvode": "cvode: setup failed: ...", "cvode: not started"
    const char* solver;    // "CVODE": "CVODE (CVode): too much work ..."
    const char* callback;  // what the callback computes: "right-hand side", "residual"
    const char* set_stop_time;
    const char* solve;
    const char* restart;
    SundialsPackage package;  // whose return codes
    void (*free_memory)(void**);  // CVodeFree, IDAFree, ...
  };

  SundialsIntegrator(const Names& names, const StepSettings& settings);  // throws if no SUNDIALS context
  ~SundialsIntegrator() override;
  SundialsIntegrator(const SundialsIntegrator&) = delete;
  SundialsIntegrator& operator=(const SundialsIntegrator&) = delete;

  // One internal step with the stop time at t_limit (the solver lands
  // exactly on it): set_stop_time(), solve(), refresh_counts().
  StepOutcome step(double t_limit) final;
  // Only at t(): the solver lands exactly on every limit.
  bool state_at(double t_target, double* out) override;
  // y() changed in place (a post-step hook): restart() from it.
  bool notify_modified() final;

 protected:
  // start()'s first part: forget the last run (release()) and take the
  // system and the initial state into y().
  void begin_start(OdeSystem& sys, double t0, const double* y0);
  // The package's calls on mem_; the int ones return its flag (< 0: failed).
  virtual bool before_step(double /*t_limit*/) { return true; }  // false: failed, failure_ says why
  virtual int set_stop_time(double t_limit) = 0;
  virtual int solve(double t_limit, double* t_returned) = 0;
  virtual double last_step() const = 0;  // 0 without mem_
  virtual void refresh_counts() = 0;     // steps_, rejected_
  virtual int restart() = 0;             // from t(), y()

  // In one-step mode the output time only sizes the solver's first trial
  // step after a (re)start (at most a tenth of the distance, less if the
  // solver's own estimate says so); the stop time is what bounds the step.
  // A far limit (1e300: "no limit") made the first trial step absurd
  // (h = 2e133 on the wheel at rest, then repeated failures), so the
  // distance is capped at 1 time unit. (Capping it at 1e4 times the last
  // step after a restart made cvode-bdf with projection take 14 million
  // steps to t = 0.1 on the slider crank, measured: the trial step then
  // shrinks with the last one.)
  double heuristic_tout(double t_limit) const;

  // Set-up helpers: a serial N_Vector over `data` (n_ values), and
  // matrix_ and linear_solver_ (dense, for yy_); false if out of memory.
  N_Vector wrap(double* data) const;
  bool make_dense_linear_solver();
  // A band matrix of half-bandwidths mu = ml = `half_bandwidth` and its LU.
  bool make_band_linear_solver(int half_bandwidth);
  bool setup_failed(const std::string& why);  // records why; false
  bool setup_failed(int flag) { return setup_failed(sundials_flag_words(names_.package, flag)); }
  StepOutcome fail(int flag, const char* where);
  // Frees the solver memory, the solvers and yy_; not ready.
  void release();

  // What the package's callbacks get as user data; from_user_data<T>()
  // turns it back.
  void* user_data() { return static_cast<SundialsIntegrator*>(this); }
  template <class T>
  static T* from_user_data(void* user_data) {
    return static_cast<T*>(static_cast<SundialsIntegrator*>(user_data));
  }
  // For a callback that failed: keeps the system's reason for fail();
  // returns 1, recoverable (the solver retries with a smaller step).
  int callback_failed(double t);
  // y' = f(t, y) by the system, for CVODE and ARKODE.
  static int rhs_callback(realtype t, N_Vector y, N_Vector ydot, void* user_data);
  // The system's own Jacobian (OdeSystem::jacobian: AD for the index-1
  // methods), for CVODE's and ARKODE's dense linear solver; at a point
  // where it has none, forward difference quotients (jac_dq_points_).
  static int jacobian_callback(realtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* user_data, N_Vector tmp1,
                               N_Vector tmp2, N_Vector tmp3);
  // Whether to pass jacobian_callback to the package: the system has a
  // Jacobian, and CSTAB_JACOBIAN=dq (a diagnostic: the packages' own
  // difference quotients, for comparison) is not set.
  bool use_system_jacobian() const;
  // "jacobian" (system or dq) and, with the system's, "jac_dq_points" as
  // summary columns.
  void append_jacobian_statistics(std::vector<std::pair<std::string, std::string>>& out) const;
  // The package's own message for the last error, kept for
  // failure_reason() instead of being printed to stderr.
  static void error_handler(int, const char*, const char* function, char* msg, void* user_data);

  StepSettings settings_;
  SUNContext ctx_ = nullptr;
  void* mem_ = nullptr;
  SundialsVector yy_;  // wraps y_: the package writes the solution straight into y()
  SUNMatrix matrix_ = nullptr;
  SUNLinearSolver linear_solver_ = nullptr;
  SUNNonlinearSolver nonlinear_solver_ = nullptr;
  bool ready_ = false;
  bool system_jacobian_ = false;  // jacobian_callback passed to the package
  long jac_dq_points_ = 0;        // Jacobians by difference quotients where the system gave none
  std::string callback_failure_, solver_message_;

 private:
  Names names_;
};

}  // namespace cstab

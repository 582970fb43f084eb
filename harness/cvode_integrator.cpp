// The "cvode-bdf" and "cvode-adams" integrators: SUNDIALS CVODE on an
// OdeSystem y' = f(t, y), driven one internal step at a time (CV_ONE_STEP
// with CVodeSetStopTime(t_limit)) so the harness observes, projects and
// detects divergence between steps, like the "ida" wrapper.
//   cvode-bdf   : variable-order BDF (orders 1-5), Newton iteration with a
//                 dense direct linear solver and CVODE's difference-quotient
//                 dense Jacobian (n extra right-hand sides per Jacobian).
//   cvode-adams : variable-order Adams-Moulton (orders 1-12), fixed-point
//                 (functional) iteration: no Jacobian, no linear solver, the
//                 usual choice for non-stiff problems.
//   cvode-projection(-noerr) : cvode-bdf with the formulation's post-step
//                 hook as CVODE's projection function (CVodeSetProjFn), with
//                 the error estimate projected or not (CVodeSetProjErrEst);
//                 the harness then leaves the hook to the integrator
//                 (applies_post_step) and CVODE keeps its history.
// Tolerances: scalar rtol and atol (CVodeSStolerances).
//
// After a post-step hook changed y() (projection), notify_modified()
// restarts CVODE from it at order 1 (CVodeReInit). CVodeReInit resets
// CVODE's counters, so the wrapper carries them across restarts (Totals).
//
// Counts: rhs_evals() is every right-hand side (CVODE's own and the
// difference-quotient Jacobian's); statistics() gives CVODE's counters as
// cvode_* summary columns. Everything is allocated in start(); a step
// allocates nothing on cstab's side (tests/unit/test_alloc.cpp runs every
// method x cvode-* step loop under an allocation counter).
#include <cvode/cvode.h>
#include <cvode/cvode_proj.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "core/format.hpp"
#include "core/params.hpp"
#include "harness/integrator.hpp"

namespace cstab {

namespace {

static_assert(std::is_same_v<realtype, double>, "SUNDIALS must be built in double precision");

std::string cvode_flag_words(int flag) {
  switch (flag) {
    case CV_TOO_MUCH_WORK: return "too much work (internal step limit reached)";
    case CV_TOO_MUCH_ACC: return "tolerances too tight for machine precision";
    case CV_ERR_FAILURE: return "repeated error-test failures (step size collapsed)";
    case CV_CONV_FAILURE: return "nonlinear iteration failed to converge repeatedly (step size collapsed)";
    case CV_LINIT_FAIL: return "linear solver initialisation failed";
    case CV_LSETUP_FAIL: return "linear solver setup failed (singular iteration matrix)";
    case CV_LSOLVE_FAIL: return "linear solve failed";
    case CV_RHSFUNC_FAIL: return "right-hand side failed unrecoverably";
    case CV_FIRST_RHSFUNC_ERR: return "right-hand side failed at the first call";
    case CV_REPTD_RHSFUNC_ERR: return "repeated recoverable right-hand-side failures";
    case CV_UNREC_RHSFUNC_ERR: return "right-hand side failed and could not recover";
    case CV_NLS_INIT_FAIL: return "nonlinear solver initialisation failed";
    case CV_NLS_SETUP_FAIL: return "nonlinear solver setup failed";
    case CV_NLS_FAIL: return "nonlinear solver failed";
    case CV_MEM_FAIL: return "out of memory";
    case CV_ILL_INPUT: return "illegal input";
    case CV_BAD_T: return "time outside the last step";
    default: {
      char* name = CVodeGetReturnFlagName(flag);  // malloc'd by SUNDIALS
      std::string words = name ? name : "unknown return code " + std::to_string(flag);
      std::free(name);
      return words;
    }
  }
}

class CvodeIntegrator final : public Integrator {
 public:
  CvodeIntegrator(const StepSettings& settings, bool bdf, int projection)
      : settings_(settings), bdf_(bdf), projection_(projection) {
    if (SUNContext_Create(nullptr, &ctx_) != 0) throw std::runtime_error("cvode: SUNContext_Create failed");
  }
  ~CvodeIntegrator() override {
    release();
    SUNContext_Free(&ctx_);
  }
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;

  void start(OdeSystem& sys, double t0, const double* y0) override {
    release();
    sys_ = &sys;
    n_ = sys.dimension();
    t_ = t0;
    h_used_ = 0;
    steps_ = rejected_ = rhs_evals_ = 0;
    failure_.clear();
    solver_message_.clear();
    rhs_failure_.clear();
    carried_.fill(0);
    projections_ = 0;
    y_.assign(y0, y0 + n_);
    auto* form = dynamic_cast<Formulation*>(&sys);
    projected_form_ = projection_ != 0 && form && form->has_post_step() ? form : nullptr;
    proj_y_.assign(n_, 0);
    proj_e_.assign(n_, 0);
    proj_p_.assign(n_, 0);
    ready_ = setup(t0);
  }

  bool applies_post_step() const override { return projected_form_ != nullptr; }

  // In one-step mode the output time only sizes the solver's first trial
  // step after a (re)start (at most a tenth of the distance, less if the
  // solver's own estimate says so); the stop time is what bounds the step.
  // A far limit (1e300: "no limit") made the first trial step absurd
  // (h = 2e133 on the wheel at rest, then repeated failures), so the
  // distance is capped at 1 time unit. (Capping it at 1e4 times the last
  // step after a restart made cvode-bdf with projection take 14 million
  // steps to t = 0.1 on the slider crank, measured: the trial step then
  // shrinks with the last one.)
  double heuristic_tout(double t_limit) const { return std::min(t_limit, t_ + 1.0); }

  StepOutcome step(double t_limit) override {
    if (!ready_) {
      if (failure_.empty()) failure_ = "cvode: not started";
      return StepOutcome::kFailed;
    }
    rhs_failure_.clear();
    int flag = CVodeSetStopTime(mem_, t_limit);
    if (flag < 0) return fail(flag, "CVodeSetStopTime");
    double t_returned = t_;
    flag = CVode(mem_, heuristic_tout(t_limit), yy_, &t_returned, CV_ONE_STEP);
    refresh_counts();
    if (flag < 0) return fail(flag, "CVode");
    t_ = t_returned;
    CVodeGetLastStep(mem_, &h_used_);
    return StepOutcome::kOk;
  }

  // Dense output (CVodeGetDky) inside the last step; the harness needs it
  // only at t(), since CVODE lands exactly on every limit.
  bool state_at(double t_target, double* out) override {
    if (t_target == t_) {
      std::copy(y_.begin(), y_.end(), out);
      return true;
    }
    if (!ready_ || !(t_target < t_) || !(t_target >= t_ - h_used_)) return false;
    N_VSetArrayPointer(out, dky_);
    const int flag = CVodeGetDky(mem_, t_target, 0, dky_);
    N_VSetArrayPointer(dky_storage_.data(), dky_);
    return flag == CV_SUCCESS;
  }

  bool notify_modified() override {
    if (!ready_) return false;
    carry_counts();
    const int flag = CVodeReInit(mem_, t_, yy_);
    if (flag < 0) {
      fail(flag, "CVodeReInit");
      return false;
    }
    uncarry_reset_counts();
    return true;
  }

  std::vector<std::pair<std::string, std::string>> statistics() const override {
    const Totals c = totals();
    int last_order = 0;
    double last_step = 0;
    if (mem_) {
      CVodeGetLastOrder(mem_, &last_order);
      CVodeGetLastStep(mem_, &last_step);
    }
    std::vector<std::pair<std::string, std::string>> out;
    for (int i = 0; i < kCounters; ++i) out.emplace_back(counter_names()[i], std::to_string(c[i]));
    out.emplace_back("cvode_restarts", std::to_string(restarts_));
    if (projected_form_) {
      long proj_fails = 0;
      if (mem_) CVodeGetNumProjFails(mem_, &proj_fails);
      out.emplace_back("cvode_projections", std::to_string(projections_));
      out.emplace_back("cvode_proj_fails", std::to_string(proj_fails));
    }
    out.emplace_back("cvode_last_order", std::to_string(last_order));
    out.emplace_back("cvode_last_step", format_exact(last_step));
    return out;
  }

 private:
  static constexpr int kCounters = 9;
  using Totals = std::array<long, kCounters>;
  static const std::array<const char*, kCounters>& counter_names() {
    static const std::array<const char*, kCounters> names = {
        "cvode_steps",           "cvode_rhs_evals",       "cvode_jac_evals",        "cvode_jac_rhs_evals",
        "cvode_lin_setups",      "cvode_nonlin_iters",    "cvode_nonlin_conv_fails", "cvode_err_test_fails",
        "cvode_step_solve_fails"};
    return names;
  }

  // CVODE's counters since its last (re)initialisation.
  Totals raw() const {
    Totals c{};
    if (!mem_) return c;
    CVodeGetNumSteps(mem_, &c[0]);
    CVodeGetNumRhsEvals(mem_, &c[1]);
    if (bdf_) {
      CVodeGetNumJacEvals(mem_, &c[2]);
      CVodeGetNumLinRhsEvals(mem_, &c[3]);
    }
    CVodeGetNumLinSolvSetups(mem_, &c[4]);
    CVodeGetNumNonlinSolvIters(mem_, &c[5]);
    CVodeGetNumNonlinSolvConvFails(mem_, &c[6]);
    CVodeGetNumErrTestFails(mem_, &c[7]);
    CVodeGetNumStepSolveFails(mem_, &c[8]);
    return c;
  }
  Totals totals() const {
    Totals c = raw();
    for (int i = 0; i < kCounters; ++i) c[i] += carried_[i];
    return c;
  }
  // Before a restart: keep what CVODE counted so far.
  void carry_counts() {
    const Totals c = raw();
    for (int i = 0; i < kCounters; ++i) carried_[i] += c[i];
    ++restarts_;
  }
  // After it: whatever the restart left in the counters is counted again
  // from there on (zero if it reset them, as CVodeReInit does).
  void uncarry_reset_counts() {
    const Totals c = raw();
    for (int i = 0; i < kCounters; ++i) carried_[i] -= c[i];
  }

  bool setup(double t0) {
    restarts_ = 0;
    yy_ = N_VMake_Serial(n_, y_.data(), ctx_);  // CVODE writes the solution straight into y()
    dky_storage_.assign(n_, 0);
    dky_ = N_VMake_Serial(n_, dky_storage_.data(), ctx_);
    if (!yy_ || !dky_) return setup_failed("out of memory");
    mem_ = CVodeCreate(bdf_ ? CV_BDF : CV_ADAMS, ctx_);
    if (!mem_) return setup_failed("out of memory");
    CVodeSetErrHandlerFn(mem_, &CvodeIntegrator::error_handler, this);
    int flag = CVodeInit(mem_, &CvodeIntegrator::rhs_callback, t0, yy_);
    if (flag == CV_SUCCESS) flag = CVodeSetUserData(mem_, this);
    if (flag == CV_SUCCESS) flag = CVodeSStolerances(mem_, settings_.rtol, settings_.atol);
    // As for ARKODE (arkode_integrator.cpp): 20 error-test failures in one
    // step before giving up, not CVODE's default 7.
    if (flag == CV_SUCCESS) flag = CVodeSetMaxErrTestFails(mem_, 20);
    if (flag != CV_SUCCESS) return setup_failed(cvode_flag_words(flag));
    if (bdf_) {
      matrix_ = SUNDenseMatrix(n_, n_, ctx_);
      if (!matrix_) return setup_failed("out of memory");
      linear_solver_ = SUNLinSol_Dense(yy_, matrix_, ctx_);
      if (!linear_solver_) return setup_failed("out of memory");
      flag = CVodeSetLinearSolver(mem_, linear_solver_, matrix_);
    } else {
      nonlinear_solver_ = SUNNonlinSol_FixedPoint(yy_, 0, ctx_);
      if (!nonlinear_solver_) return setup_failed("out of memory");
      flag = CVodeSetNonlinearSolver(mem_, nonlinear_solver_);
    }
    if (flag != CV_SUCCESS) return setup_failed(cvode_flag_words(flag));
    if (projected_form_) {
      flag = CVodeSetProjFn(mem_, &CvodeIntegrator::projection_callback);
      if (flag == CV_SUCCESS) flag = CVodeSetProjErrEst(mem_, projection_ == 1 ? SUNTRUE : SUNFALSE);
      if (flag != CV_SUCCESS) return setup_failed(cvode_flag_words(flag));
    }
    return true;
  }

  // CVODE's projection: corr with ycur + corr on the manifold, by the
  // method's own post-step hook (projection: mass-weighted Gauss-Newton on
  // the positions, then the velocities; post-stabilization: one
  // correction). With the error estimate projected, err becomes
  // Proj(p + err) - Proj(p), p = ycur + corr: its part along the manifold.
  static int projection_callback(realtype t, N_Vector ycur, N_Vector corr, realtype, N_Vector err,
                                 void* user_data) {
    auto* self = static_cast<CvodeIntegrator*>(user_data);
    const int n = self->n_;
    const double* y = N_VGetArrayPointer(ycur);
    double* c = N_VGetArrayPointer(corr);
    double* p = self->proj_y_.data();
    std::copy(y, y + n, p);
    ++self->projections_;
    self->projected_form_->post_step(t, p);
    for (int i = 0; i < n; ++i) {
      c[i] = p[i] - y[i];
      if (!std::isfinite(c[i])) return 1;  // recoverable: CVODE retries with a smaller step
    }
    if (err) {
      // Linearized: Proj(p + e) - Proj(p), so that a hook that is not
      // idempotent (post-stabilization's single correction) does not add
      // its own correction of p to the error (measured: with
      // Proj(p + e) - p, biped with post-stabilization failed at t = 0, the
      // error test failing down to h = 1e-29).
      double* e = N_VGetArrayPointer(err);
      double* pe = self->proj_e_.data();
      double* pp = self->proj_p_.data();
      for (int i = 0; i < n; ++i) pe[i] = p[i] + e[i], pp[i] = p[i];
      self->projected_form_->post_step(t, pe);
      self->projected_form_->post_step(t, pp);
      for (int i = 0; i < n; ++i) e[i] = pe[i] - pp[i];
    }
    return 0;
  }

  bool setup_failed(const std::string& why) {
    failure_ = "cvode: setup failed: " + why + (solver_message_.empty() ? "" : " (" + solver_message_ + ")");
    return false;
  }

  void release() {
    if (mem_) CVodeFree(&mem_);
    if (linear_solver_) SUNLinSolFree(linear_solver_);
    if (nonlinear_solver_) SUNNonlinSolFree(nonlinear_solver_);
    if (matrix_) SUNMatDestroy(matrix_);
    for (N_Vector* v : {&yy_, &dky_}) {
      if (*v) N_VDestroy(*v);
      *v = nullptr;
    }
    mem_ = nullptr;
    linear_solver_ = nullptr;
    nonlinear_solver_ = nullptr;
    matrix_ = nullptr;
    ready_ = false;
  }

  void refresh_counts() {
    const Totals c = totals();
    steps_ = c[0];
    rejected_ = c[7] + c[8];  // error-test failures and failed nonlinear solves
  }

  StepOutcome fail(int flag, const char* where) {
    failure_ = "CVODE (" + std::string(where) + "): " + cvode_flag_words(flag);
    if (!rhs_failure_.empty()) failure_ += "; right-hand side: " + rhs_failure_;
    if (!solver_message_.empty()) failure_ += " [" + solver_message_ + "]";
    return StepOutcome::kFailed;
  }

  static int rhs_callback(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
    auto* self = static_cast<CvodeIntegrator*>(user_data);
    ++self->rhs_evals_;
    if (self->sys_->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot))) return 0;
    self->rhs_failure_ = self->sys_->failure_reason();
    if (self->rhs_failure_.empty()) self->rhs_failure_ = "right-hand side failed at t = " + format_short(t);
    return 1;  // recoverable: CVODE retries with a smaller step
  }

  // CVODE's own message for the last error, kept for failure_reason()
  // instead of being printed to stderr.
  static void error_handler(int, const char*, const char* function, char* msg, void* user_data) {
    auto* self = static_cast<CvodeIntegrator*>(user_data);
    self->solver_message_ = std::string(function) + ": " + msg;
  }

  StepSettings settings_;
  bool bdf_;
  int projection_;  // 0 none, 1 CVodeSetProjFn with the error estimate projected, 2 without
  Formulation* projected_form_ = nullptr;
  std::vector<double> proj_y_, proj_e_, proj_p_;
  long projections_ = 0;
  SUNContext ctx_ = nullptr;
  void* mem_ = nullptr;
  N_Vector yy_ = nullptr, dky_ = nullptr;
  std::vector<double> dky_storage_;
  SUNMatrix matrix_ = nullptr;
  SUNLinearSolver linear_solver_ = nullptr;
  SUNNonlinearSolver nonlinear_solver_ = nullptr;
  bool ready_ = false;
  Totals carried_{};
  long restarts_ = 0;
  std::string rhs_failure_, solver_message_;
};

}  // namespace

std::unique_ptr<Integrator> make_cvode_integrator(const StepSettings& settings, bool bdf, int projection) {
  return std::make_unique<CvodeIntegrator>(settings, bdf, projection);
}

}  // namespace cstab

// The "cvode-bdf" and "cvode-adams" integrators: SUNDIALS CVODE on an
// OdeSystem y' = f(t, y), driven one internal step at a time (CV_ONE_STEP
// with CVodeSetStopTime(t_limit)) so the harness observes, projects and
// detects divergence between steps, like the "ida" wrapper.
//   cvode-bdf   : variable-order BDF (orders 1-5), Newton iteration with a
//                 dense direct linear solver and the system's Jacobian where
//                 it has one (OdeSystem::jacobian: AD for the index-1
//                 methods), otherwise CVODE's difference-quotient dense
//                 Jacobian (n extra right-hand sides per Jacobian).
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
// CVODE's counters, so the wrapper carries them across restarts
// (CarriedCounts, sundials_common.hpp).
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
#include <memory>

#include "core/format.hpp"
#include "core/params.hpp"
#include "harness/integrator.hpp"
#include "harness/sundials_common.hpp"

namespace cstab {

namespace {

constexpr SundialsIntegrator::Names kCvodeNames = {
    "cvode", "CVODE", "right-hand side", "CVodeSetStopTime", "CVode", "CVodeReInit", SundialsPackage::kCvode,
    CVodeFree};

class CvodeIntegrator final : public SundialsIntegrator {
 public:
  CvodeIntegrator(const StepSettings& settings, bool bdf, int projection)
      : SundialsIntegrator(kCvodeNames, settings), bdf_(bdf), projection_(projection) {}
  ~CvodeIntegrator() override { release(); }  // the solver memory before the vectors below

  void start(OdeSystem& sys, double t0, const double* y0) override {
    begin_start(sys, t0, y0);
    counts_.clear();
    projections_ = 0;
    auto* form = dynamic_cast<Formulation*>(&sys);
    projected_form_ = projection_ != 0 && form && form->has_post_step() ? form : nullptr;
    proj_y_.assign(n_, 0);
    proj_e_.assign(n_, 0);
    proj_p_.assign(n_, 0);
    ready_ = setup(t0);
  }

  bool applies_post_step() const override { return projected_form_ != nullptr; }

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

  std::vector<std::pair<std::string, std::string>> statistics() const override {
    int last_order = 0;
    if (mem_) CVodeGetLastOrder(mem_, &last_order);
    std::vector<std::pair<std::string, std::string>> out;
    counts_.append(out, raw());
    out.emplace_back("cvode_restarts", std::to_string(counts_.restarts()));
    if (bdf_) append_jacobian_statistics(out);
    if (projected_form_) {
      long proj_fails = 0;
      if (mem_) CVodeGetNumProjFails(mem_, &proj_fails);
      out.emplace_back("cvode_projections", std::to_string(projections_));
      out.emplace_back("cvode_proj_fails", std::to_string(proj_fails));
    }
    out.emplace_back("cvode_last_order", std::to_string(last_order));
    out.emplace_back("cvode_last_step", format_exact(last_step()));
    return out;
  }

 private:
  using Counters = CarriedCounts<9>;

  // CVODE's counters since its last (re)initialisation, in counts_' order
  // (no Jacobian without the linear solver: cvode-adams).
  Counters::Counts raw() const {
    return Counters::read(mem_, {CVodeGetNumSteps, CVodeGetNumRhsEvals, bdf_ ? CVodeGetNumJacEvals : nullptr,
                                 bdf_ ? CVodeGetNumLinRhsEvals : nullptr, CVodeGetNumLinSolvSetups,
                                 CVodeGetNumNonlinSolvIters, CVodeGetNumNonlinSolvConvFails, CVodeGetNumErrTestFails,
                                 CVodeGetNumStepSolveFails});
  }

  int set_stop_time(double t_limit) override { return CVodeSetStopTime(mem_, t_limit); }
  int solve(double t_limit, double* t_returned) override {
    const int flag = CVode(mem_, heuristic_tout(t_limit), yy_, t_returned, CV_ONE_STEP);
    counts_.solved();
    return flag;
  }
  double last_step() const override {
    double h = 0;
    if (mem_) CVodeGetLastStep(mem_, &h);
    return h;
  }
  void refresh_counts() override {
    const Counters::Counts c = counts_.totals(raw());
    steps_ = c[0];
    rejected_ = c[7] + c[8];  // error-test failures and failed nonlinear solves
  }
  // At order 1; CVodeReInit resets CVODE's counters, so they are carried.
  int restart() override {
    counts_.before_restart(raw());
    const int flag = CVodeReInit(mem_, t_, yy_);
    if (flag >= 0) counts_.after_restart(raw());
    return flag;
  }

  bool setup(double t0) {
    yy_.reset(wrap(y_.data()));
    dky_storage_.assign(n_, 0);
    dky_.reset(wrap(dky_storage_.data()));
    if (!yy_ || !dky_) return setup_failed("out of memory");
    mem_ = CVodeCreate(bdf_ ? CV_BDF : CV_ADAMS, ctx_);
    if (!mem_) return setup_failed("out of memory");
    CVodeSetErrHandlerFn(mem_, &SundialsIntegrator::error_handler, user_data());
    int flag = CVodeInit(mem_, &SundialsIntegrator::rhs_callback, t0, yy_);
    if (flag == CV_SUCCESS) flag = CVodeSetUserData(mem_, user_data());
    if (flag == CV_SUCCESS) flag = CVodeSStolerances(mem_, settings_.rtol, settings_.atol);
    // As for ARKODE (arkode_integrator.cpp): 20 error-test failures in one
    // step before giving up, not CVODE's default 7.
    if (flag == CV_SUCCESS) flag = CVodeSetMaxErrTestFails(mem_, 20);
    if (flag != CV_SUCCESS) return setup_failed(flag);
    if (bdf_) {
      if (!make_dense_linear_solver()) return setup_failed("out of memory");
      flag = CVodeSetLinearSolver(mem_, linear_solver_, matrix_);
      system_jacobian_ = use_system_jacobian();
      if (flag == CV_SUCCESS && system_jacobian_) flag = CVodeSetJacFn(mem_, &SundialsIntegrator::jacobian_callback);
    } else {
      nonlinear_solver_ = SUNNonlinSol_FixedPoint(yy_, 0, ctx_);
      if (!nonlinear_solver_) return setup_failed("out of memory");
      flag = CVodeSetNonlinearSolver(mem_, nonlinear_solver_);
    }
    if (flag != CV_SUCCESS) return setup_failed(flag);
    if (projected_form_) {
      flag = CVodeSetProjFn(mem_, &CvodeIntegrator::projection_callback);
      if (flag == CV_SUCCESS) flag = CVodeSetProjErrEst(mem_, projection_ == 1 ? SUNTRUE : SUNFALSE);
      if (flag != CV_SUCCESS) return setup_failed(flag);
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
    auto* self = from_user_data<CvodeIntegrator>(user_data);
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

  bool bdf_;
  int projection_;  // 0 none, 1 CVodeSetProjFn with the error estimate projected, 2 without
  Formulation* projected_form_ = nullptr;
  std::vector<double> proj_y_, proj_e_, proj_p_;
  long projections_ = 0;
  SundialsVector dky_;  // CVodeGetDky's output, pointed at the caller's array
  std::vector<double> dky_storage_;
  Counters counts_{{"cvode_steps", "cvode_rhs_evals", "cvode_jac_evals", "cvode_jac_rhs_evals", "cvode_lin_setups",
                     "cvode_nonlin_iters", "cvode_nonlin_conv_fails", "cvode_err_test_fails",
                     "cvode_step_solve_fails"},
                    // the linear solver's (Jacobian evaluations and their
                    // right-hand sides) are reset at the next CVode call
                    {false, false, true, true, false, false, false, false, false}};
};

}  // namespace

std::unique_ptr<Integrator> make_cvode_integrator(const StepSettings& settings, bool bdf, int projection) {
  return std::make_unique<CvodeIntegrator>(settings, bdf, projection);
}

}  // namespace cstab

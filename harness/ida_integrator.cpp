// The "ida" integrator: SUNDIALS IDA (variable-order, variable-step BDF) on a
// DaeSystem F(t, y, y') = 0, driven one internal step at a time so the
// harness observes between steps. Set-up follows the SUNDIALS example
// idasSlCrank_dns: IDASetId marks the algebraic components, their error
// control is suppressed (IDASetSuppressAlg; standard for index-2 GGL), a
// dense direct linear solver with IDA's difference-quotient Jacobian.
// For an index-1 DAE, IDACalcIC(IDA_YA_YDP_INIT) makes the initial algebraic
// y and differential y' consistent before the first step; a higher-index DAE
// (ida-ggl) supplies consistent values and they are checked (see
// make_consistent). IDASetStopTime(t_limit) makes IDA land exactly on every
// output time.
//
// Counts: rhs_evals() is every residual evaluation (IDA's own, the
// difference-quotient Jacobian's and the initial-value calculation's);
// statistics() gives IDA's counters as ida_* summary columns.
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <memory>

#include "core/format.hpp"
#include "core/params.hpp"
#include "harness/integrator.hpp"
#include "harness/sundials_common.hpp"

namespace cstab {

namespace {

constexpr SundialsIntegrator::Names kIdaNames = {
    "ida", "IDA", "residual", "IDASetStopTime", "IDASolve", "IDAReInit", SundialsPackage::kIda, IDAFree};

class IdaIntegrator final : public SundialsIntegrator {
 public:
  explicit IdaIntegrator(const StepSettings& settings) : SundialsIntegrator(kIdaNames, settings) {}
  ~IdaIntegrator() override { release(); }  // the solver memory before the vectors below

  void start(OdeSystem& sys, double t0, const double* y0) override {
    begin_start(sys, t0, y0);
    need_initial_condition_ = true;
    dae_ = dynamic_cast<DaeSystem*>(&sys);
    if (!dae_) {
      failure_ = "ida: the formulation is not a DAE F(t, y, y') = 0 (use a DAE method: ida-index1, ida-ggl)";
      return;
    }
    if (dae_->dae_dimension() != n_) {
      failure_ = "ida: DAE dimension " + std::to_string(dae_->dae_dimension()) +
                 " differs from the formulation's dimension " + std::to_string(n_);
      return;
    }
    yp_.assign(n_, 0);
    scratch_.assign(n_, 0);
    // y from the harness (the formulation's initial state); y' guessed by the DAE.
    dae_->initial_values(t0, scratch_.data(), yp_.data());
    ready_ = setup(t0);
  }

  std::vector<std::pair<std::string, std::string>> statistics() const override {
    long steps = 0, res_evals = 0, jac_evals = 0, jac_res_evals = 0, nonlin_iters = 0, err_test_fails = 0,
         nonlin_conv_fails = 0;
    int last_order = 0;
    if (mem_) {
      IDAGetNumSteps(mem_, &steps);
      IDAGetNumResEvals(mem_, &res_evals);
      IDAGetNumJacEvals(mem_, &jac_evals);
      IDAGetNumLinResEvals(mem_, &jac_res_evals);
      IDAGetNumNonlinSolvIters(mem_, &nonlin_iters);
      IDAGetNumErrTestFails(mem_, &err_test_fails);
      IDAGetNumNonlinSolvConvFails(mem_, &nonlin_conv_fails);
      IDAGetLastOrder(mem_, &last_order);
    }
    return {{"ida_steps", std::to_string(steps)},
            {"ida_res_evals", std::to_string(res_evals)},
            {"ida_jac_evals", std::to_string(jac_evals)},
            {"ida_jac_res_evals", std::to_string(jac_res_evals)},
            {"ida_nonlin_iters", std::to_string(nonlin_iters)},
            {"ida_err_test_fails", std::to_string(err_test_fails)},
            {"ida_nonlin_conv_fails", std::to_string(nonlin_conv_fails)},
            {"ida_last_order", std::to_string(last_order)},
            {"ida_last_step", format_exact(last_step())}};
  }

 private:
  // Before the first step after a (re)start: consistent initial values.
  bool before_step(double t_limit) override {
    solver_message_.clear();
    if (!need_initial_condition_) return true;
    if (!make_consistent(t_limit)) return false;
    need_initial_condition_ = false;
    estimate_first_step(t_limit);
    return true;
  }
  int set_stop_time(double t_limit) override { return IDASetStopTime(mem_, t_limit); }
  int solve(double t_limit, double* t_returned) override {
    return IDASolve(mem_, t_limit, t_returned, yy_, ypp_, IDA_ONE_STEP);
  }
  double last_step() const override {
    double h = 0;
    if (mem_) IDAGetLastStep(mem_, &h);
    return h;
  }
  void refresh_counts() override {
    long steps = 0, err_test_fails = 0, solve_fails = 0;
    IDAGetNumSteps(mem_, &steps);
    IDAGetNumErrTestFails(mem_, &err_test_fails);
    IDAGetNumStepSolveFails(mem_, &solve_fails);
    steps_ = steps;
    rejected_ = err_test_fails + solve_fails;
  }
  // At order 1; the algebraic components are made consistent again before
  // the next step.
  int restart() override {
    const int flag = IDAReInit(mem_, t_, yy_, ypp_);
    if (flag >= 0) need_initial_condition_ = true;
    return flag;
  }

  bool setup(double t0) {
    // yy_/ypp_ wrap y_/yp_: IDA writes the solution straight into y().
    yy_.reset(wrap(y_.data()));
    ypp_.reset(wrap(yp_.data()));
    id_.reset(N_VNew_Serial(n_, ctx_));
    const int band = dae_->half_bandwidth();
    const bool solver = band >= 0 && band < n_ - 1 ? make_band_linear_solver(band) : make_dense_linear_solver();
    if (!yy_ || !ypp_ || !id_ || !solver) return setup_failed("out of memory");
    mem_ = IDACreate(ctx_);
    if (!mem_) return setup_failed("out of memory");
    dae_->component_ids(N_VGetArrayPointer(id_));
    IDASetErrHandlerFn(mem_, &SundialsIntegrator::error_handler, user_data());
    int flag = IDAInit(mem_, &IdaIntegrator::residual_callback, t0, yy_, ypp_);
    if (flag == IDA_SUCCESS) flag = IDASetUserData(mem_, user_data());
    if (flag == IDA_SUCCESS) flag = IDAWFtolerances(mem_, &IdaIntegrator::error_weights);
    if (flag == IDA_SUCCESS) flag = IDASetId(mem_, id_);
    if (flag == IDA_SUCCESS) flag = IDASetSuppressAlg(mem_, SUNTRUE);
    if (flag == IDA_SUCCESS) flag = IDASetLinearSolver(mem_, linear_solver_, matrix_);
    if (flag != IDA_SUCCESS) return setup_failed(flag);
    return true;
  }

  // IDA's initial step: 0.001 |tout - t0|, at most 0.5 / ||y'||_WRMS over
  // the differential components (weights divided by all n, as IDA does).
  void estimate_first_step(double t_limit) {
    double sum = 0;
    const double* id = N_VGetArrayPointer(id_);
    for (int i = 0; i < n_; ++i) {
      if (id[i] < 0.5) continue;
      const double w = yp_[i] / (settings_.rtol * std::abs(y_[i]) + settings_.atol);
      sum += w * w;
    }
    const double yp_norm = std::sqrt(sum / n_);
    first_step_estimate_ = 0.001 * std::abs(t_limit - t_);
    if (yp_norm > 0.5 / first_step_estimate_) first_step_estimate_ = 0.5 / yp_norm;
  }

  // Consistent initial values before the first step.
  bool make_consistent(double t_limit) {
    if (dae_->index() <= 1) {
      // Algebraic components of y and differential components of y' from
      // the differential components of y; tout1 only sets the trial step.
      in_calc_ic_ = true;
      const int flag = IDACalcIC(mem_, IDA_YA_YDP_INIT, t_limit);
      in_calc_ic_ = false;
      if (flag < 0) {
        fail(flag, "consistent initial values (IDACalcIC)");
        return false;
      }
      IDAGetConsistentIC(mem_, yy_, ypp_);
      return true;
    }
    // IDACalcIC is for index 1: on an index-2 system its Newton iteration
    // (trial step ~ 0.5 / ||y'||_WRMS, tiny at tight tolerances) makes the
    // index-2 multipliers' corrections scale like 1/h^2, and it fails
    // (measured on the wheel with ida-ggl at rtol = atol = 1e-8). The DAE
    // supplies consistent values itself; check F(t0, y0, y0') = 0.
    ++rhs_evals_;
    if (!dae_->residual(t_, y_.data(), yp_.data(), scratch_.data())) {
      failure_ = "ida: residual failed at the initial values: " + sys_->failure_reason();
      return false;
    }
    int worst = 0;
    for (int i = 1; i < n_; ++i)
      if (!(std::abs(scratch_[i]) <= std::abs(scratch_[worst]))) worst = i;
    if (!(std::abs(scratch_[worst]) <= settings_.atol)) {
      failure_ = "ida: inconsistent initial values for an index-" + std::to_string(dae_->index()) +
                 " DAE: |F| = " + format_short(std::abs(scratch_[worst])) + " at component " +
                 std::to_string(worst) + " exceeds atol (IDACalcIC handles index 1 only; start from "
                 "positions and velocities that satisfy the constraints, or use ida-index1)";
      return false;
    }
    return true;
  }

  static int residual_callback(realtype t, N_Vector y, N_Vector yp, N_Vector r, void* user_data) {
    auto* self = from_user_data<IdaIntegrator>(user_data);
    ++self->rhs_evals_;
    if (self->dae_->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(r)))
      return 0;
    return self->callback_failed(t);
  }

  // Error weights 1 / (rtol |y_i| + atol) for the differential components.
  // The algebraic ones (multipliers) are out of the error test
  // (IDASetSuppressAlg) and matter only in the Newton convergence test (and
  // as difference-quotient increments 1/w); a multiplier error d changes the
  // differential variables by about h d in one step, so it is weighted by
  // h / (rtol |y_i| + atol). With the plain weight the test demands the
  // multipliers to atol, which an index-2 system cannot give at small h
  // (their roundoff grows like 1/h): on the wheel with ida-ggl at
  // rtol = atol = 1e-8 the first step collapsed to h = 1e-17 and failed.
  // Before the first step (h = 0) IDA's own initial-step formula stands in
  // for h; while IDACalcIC computes them they keep the plain weight.
  static int error_weights(N_Vector y, N_Vector ewt, void* user_data) {
    auto* self = from_user_data<IdaIntegrator>(user_data);
    double h = 0;
    IDAGetCurrentStep(self->mem_, &h);
    if (h == 0) h = self->first_step_estimate_;
    const double algebraic_scale = self->in_calc_ic_ ? 1.0 : std::abs(h);
    const double* yv = N_VGetArrayPointer(y);
    const double* id = N_VGetArrayPointer(self->id_);
    double* w = N_VGetArrayPointer(ewt);
    for (int i = 0; i < self->n_; ++i) {
      const double tol = self->settings_.rtol * std::abs(yv[i]) + self->settings_.atol;
      w[i] = (id[i] > 0.5 ? 1.0 : algebraic_scale) / tol;
    }
    return 0;
  }

  SundialsVector ypp_, id_;  // y' (wraps yp_), the differential (1) / algebraic (0) components
  DaeSystem* dae_ = nullptr;
  std::vector<double> yp_, scratch_;
  bool need_initial_condition_ = true;
  bool in_calc_ic_ = false;
  double first_step_estimate_ = 1.0;  // stands in for h before the first step
};

}  // namespace

std::unique_ptr<Integrator> make_ida_integrator(const StepSettings& settings) {
  return std::make_unique<IdaIntegrator>(settings);
}

}  // namespace cstab

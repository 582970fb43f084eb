// The SUNDIALS wrappers' common part (sundials_common.hpp).
#include "harness/sundials_common.hpp"

#include <arkode/arkode_arkstep.h>
#include <cvode/cvode.h>
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "core/format.hpp"

namespace cstab {

namespace {

// What each package's return codes mean, in words: the code in CVODE,
// ARKODE and IDA; 0 (success in all three) where that package has no such
// code, words it differently in another row, or is left to the package's
// own name for it.
struct FlagWords {
  int cvode, arkode, ida;
  const char* words;
};
constexpr FlagWords kFlagWords[] = {
    {CV_TOO_MUCH_WORK, ARK_TOO_MUCH_WORK, IDA_TOO_MUCH_WORK, "too much work (internal step limit reached)"},
    {CV_TOO_MUCH_ACC, ARK_TOO_MUCH_ACC, IDA_TOO_MUCH_ACC, "tolerances too tight for machine precision"},
    {CV_ERR_FAILURE, ARK_ERR_FAILURE, IDA_ERR_FAIL, "repeated error-test failures (step size collapsed)"},
    {CV_CONV_FAILURE, ARK_CONV_FAILURE, 0, "nonlinear iteration failed to converge repeatedly (step size collapsed)"},
    {0, 0, IDA_CONV_FAIL, "Newton iteration failed to converge repeatedly (step size collapsed)"},
    {CV_LINIT_FAIL, 0, IDA_LINIT_FAIL, "linear solver initialisation failed"},
    {CV_LSETUP_FAIL, ARK_LSETUP_FAIL, IDA_LSETUP_FAIL, "linear solver setup failed (singular iteration matrix)"},
    {CV_LSOLVE_FAIL, ARK_LSOLVE_FAIL, IDA_LSOLVE_FAIL, "linear solve failed"},
    {CV_RHSFUNC_FAIL, ARK_RHSFUNC_FAIL, 0, "right-hand side failed unrecoverably"},
    {0, 0, IDA_RES_FAIL, "residual evaluation failed unrecoverably"},
    {CV_FIRST_RHSFUNC_ERR, ARK_FIRST_RHSFUNC_ERR, 0, "right-hand side failed at the first call"},
    {CV_REPTD_RHSFUNC_ERR, ARK_REPTD_RHSFUNC_ERR, 0, "repeated recoverable right-hand-side failures"},
    {0, 0, IDA_REP_RES_ERR, "repeated recoverable residual failures"},
    {CV_UNREC_RHSFUNC_ERR, ARK_UNREC_RHSFUNC_ERR, 0, "right-hand side failed and could not recover"},
    {0, 0, IDA_CONSTR_FAIL, "inequality constraints could not be met"},
    {0, 0, IDA_FIRST_RES_FAIL, "residual failed at the first call of the initial-value calculation"},
    {0, 0, IDA_LINESEARCH_FAIL, "line search failed in the initial-value calculation"},
    {0, 0, IDA_NO_RECOVERY, "initial-value calculation could not recover from a residual or linear-solver failure"},
    {CV_NLS_INIT_FAIL, 0, IDA_NLS_INIT_FAIL, "nonlinear solver initialisation failed"},
    {CV_NLS_SETUP_FAIL, 0, IDA_NLS_SETUP_FAIL, "nonlinear solver setup failed"},
    {CV_NLS_FAIL, 0, IDA_NLS_FAIL, "nonlinear solver failed"},
    {CV_MEM_FAIL, ARK_MEM_FAIL, IDA_MEM_FAIL, "out of memory"},
    {CV_ILL_INPUT, ARK_ILL_INPUT, IDA_ILL_INPUT, "illegal input"},
    {0, 0, IDA_BAD_EWT, "an error weight became non-positive"},
    {CV_BAD_T, 0, IDA_BAD_T, "time outside the last step"},
};

}  // namespace

std::string sundials_flag_words(SundialsPackage package, int flag) {
  for (const FlagWords& w : kFlagWords) {
    const int code = package == SundialsPackage::kCvode    ? w.cvode
                     : package == SundialsPackage::kArkode ? w.arkode
                                                           : w.ida;
    if (code == flag && code != 0) return w.words;
  }
  char* name = package == SundialsPackage::kCvode    ? CVodeGetReturnFlagName(flag)
               : package == SundialsPackage::kArkode ? ARKStepGetReturnFlagName(flag)
                                                     : IDAGetReturnFlagName(flag);  // malloc'd by SUNDIALS
  std::string words = name ? name : "unknown return code " + std::to_string(flag);
  std::free(name);
  return words;
}

SundialsIntegrator::SundialsIntegrator(const Names& names, const StepSettings& settings)
    : settings_(settings), names_(names) {
  if (SUNContext_Create(nullptr, &ctx_) != 0)
    throw std::runtime_error(std::string(names_.tag) + ": SUNContext_Create failed");
}

SundialsIntegrator::~SundialsIntegrator() {
  release();
  SUNContext_Free(&ctx_);
}

void SundialsIntegrator::begin_start(OdeSystem& sys, double t0, const double* y0) {
  release();
  sys_ = &sys;
  n_ = sys.dimension();
  t_ = t0;
  h_used_ = 0;
  steps_ = rejected_ = rhs_evals_ = 0;
  failure_.clear();
  solver_message_.clear();
  callback_failure_.clear();
  y_.assign(y0, y0 + n_);
  system_jacobian_ = false;
  jac_dq_points_ = 0;
}

StepOutcome SundialsIntegrator::step(double t_limit) {
  if (!ready_) {
    if (failure_.empty()) failure_ = std::string(names_.tag) + ": not started";
    return StepOutcome::kFailed;
  }
  callback_failure_.clear();
  if (!before_step(t_limit)) return StepOutcome::kFailed;
  int flag = set_stop_time(t_limit);
  if (flag < 0) return fail(flag, names_.set_stop_time);
  double t_returned = t_;
  flag = solve(t_limit, &t_returned);
  refresh_counts();
  if (flag < 0) return fail(flag, names_.solve);
  t_ = t_returned;
  h_used_ = last_step();
  return StepOutcome::kOk;
}

bool SundialsIntegrator::state_at(double t_target, double* out) {
  if (t_target != t_) return false;
  std::copy(y_.begin(), y_.end(), out);
  return true;
}

bool SundialsIntegrator::notify_modified() {
  if (!ready_) return false;
  const int flag = restart();
  if (flag < 0) {
    fail(flag, names_.restart);
    return false;
  }
  return true;
}

double SundialsIntegrator::heuristic_tout(double t_limit) const { return std::min(t_limit, t_ + 1.0); }

N_Vector SundialsIntegrator::wrap(double* data) const { return N_VMake_Serial(n_, data, ctx_); }

bool SundialsIntegrator::make_dense_linear_solver() {
  matrix_ = SUNDenseMatrix(n_, n_, ctx_);
  linear_solver_ = matrix_ ? SUNLinSol_Dense(yy_, matrix_, ctx_) : nullptr;
  return linear_solver_ != nullptr;
}

bool SundialsIntegrator::make_band_linear_solver(int half_bandwidth) {
  matrix_ = SUNBandMatrix(n_, half_bandwidth, half_bandwidth, ctx_);
  linear_solver_ = matrix_ ? SUNLinSol_Band(yy_, matrix_, ctx_) : nullptr;
  return linear_solver_ != nullptr;
}

bool SundialsIntegrator::setup_failed(const std::string& why) {
  failure_ = std::string(names_.tag) + ": setup failed: " + why +
             (solver_message_.empty() ? "" : " (" + solver_message_ + ")");
  return false;
}

StepOutcome SundialsIntegrator::fail(int flag, const char* where) {
  failure_ = std::string(names_.solver) + " (" + where + "): " + sundials_flag_words(names_.package, flag);
  if (!callback_failure_.empty()) failure_ += "; " + std::string(names_.callback) + ": " + callback_failure_;
  if (!solver_message_.empty()) failure_ += " [" + solver_message_ + "]";
  return StepOutcome::kFailed;
}

void SundialsIntegrator::release() {
  if (mem_) names_.free_memory(&mem_);
  if (linear_solver_) SUNLinSolFree(linear_solver_);
  if (nonlinear_solver_) SUNNonlinSolFree(nonlinear_solver_);
  if (matrix_) SUNMatDestroy(matrix_);
  yy_.reset();
  mem_ = nullptr;
  linear_solver_ = nullptr;
  nonlinear_solver_ = nullptr;
  matrix_ = nullptr;
  ready_ = false;
}

int SundialsIntegrator::callback_failed(double t) {
  callback_failure_ = sys_->failure_reason();
  if (callback_failure_.empty()) callback_failure_ = std::string(names_.callback) + " failed at t = " + format_short(t);
  return 1;
}

int SundialsIntegrator::rhs_callback(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* me = from_user_data<SundialsIntegrator>(user_data);
  ++me->rhs_evals_;
  if (me->sys_->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot))) return 0;
  return me->callback_failed(t);
}

bool SundialsIntegrator::use_system_jacobian() const {
  const char* mode = std::getenv("CSTAB_JACOBIAN");
  return !(mode && std::string(mode) == "dq") && sys_ && sys_->has_jacobian();
}

void SundialsIntegrator::append_jacobian_statistics(std::vector<std::pair<std::string, std::string>>& out) const {
  out.emplace_back("jacobian", system_jacobian_ ? "system" : "dq");
  if (system_jacobian_) out.emplace_back("jac_dq_points", std::to_string(jac_dq_points_));
}

int SundialsIntegrator::jacobian_callback(realtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* user_data,
                                          N_Vector tmp1, N_Vector tmp2, N_Vector) {
  auto* me = from_user_data<SundialsIntegrator>(user_data);
  const int n = me->n_;
  double* jac = SUNDenseMatrix_Data(J);
  const double* yv = N_VGetArrayPointer(y);
  if (me->sys_->jacobian(t, yv, jac)) return 0;
  // Forward differences, the increment as SUNDIALS' own dense ones take it
  // (sqrt(unit round-off) relative, with an absolute floor at the
  // tolerances' scale).
  ++me->jac_dq_points_;
  const double* f0 = N_VGetArrayPointer(fy);
  double* yp = N_VGetArrayPointer(tmp1);
  double* fp = N_VGetArrayPointer(tmp2);
  std::copy(yv, yv + n, yp);
  const double srur = std::sqrt(2.220446049250313e-16);
  const double floor = me->settings_.rtol > 0 ? me->settings_.atol / me->settings_.rtol : 1.0;
  for (int j = 0; j < n; ++j) {
    const double inc = srur * std::max({std::abs(yv[j]), floor, 1e-300});
    yp[j] = yv[j] + inc;
    ++me->rhs_evals_;
    if (!me->sys_->rhs(t, yp, fp)) return me->callback_failed(t);
    for (int i = 0; i < n; ++i) jac[i + j * n] = (fp[i] - f0[i]) / inc;
    yp[j] = yv[j];
  }
  return 0;
}

void SundialsIntegrator::error_handler(int, const char*, const char* function, char* msg, void* user_data) {
  from_user_data<SundialsIntegrator>(user_data)->solver_message_ = std::string(function) + ": " + msg;
}

}  // namespace cstab

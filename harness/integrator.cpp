#include "harness/integrator.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "core/format.hpp"
#include "core/params.hpp"

namespace cstab {

void add_arkode_integrators(std::vector<IntegratorInfo>& list);         // arkode_integrator.cpp
std::string arkode_unknown_table(const std::string& name);              // arkode_integrator.cpp

const std::vector<IntegratorInfo>& all_integrators() {
  static const std::vector<IntegratorInfo> list = [] {
    std::vector<IntegratorInfo> l = {
        {"euler", "explicit (forward) Euler, fixed step", true, 1},
        {"rk4", "classical 4th-order Runge-Kutta, fixed step", true, 4},
        {"adams", "Adams-Bashforth-Moulton PECE, 4th order, fixed step (RK4 start-up)", true, 4},
        {"rk8pd", "GSL Prince-Dormand 8(9), adaptive", false, 8},
        {"rkf45", "GSL Runge-Kutta-Fehlberg 4(5), adaptive", false, 5},
        {"msadams", "GSL variable-order Adams (orders 1-12), adaptive", false, 12},
        {"msbdf",
         "GSL variable-order BDF (orders 1-5), adaptive, implicit; the method's own Jacobian by AD where "
         "it has one (index-1 methods), else difference quotients",
         false, 5},
        {"ida",
         "SUNDIALS IDA variable-order BDF (orders 1-5) for DAEs F(t, y, y') = 0, adaptive; "
         "needs a DAE method (ida-index1, ida-ggl)",
         false, 5, MethodKind::kDae},
        {"cvode-bdf",
         "SUNDIALS CVODE variable-order BDF (orders 1-5), adaptive, implicit: Newton with a dense "
         "Jacobian, the method's own by AD where it has one (index-1 methods), else difference "
         "quotients",
         false, 5},
        {"cvode-adams", "SUNDIALS CVODE variable-order Adams-Moulton (orders 1-12), adaptive, fixed-point iteration",
         false, 12},
        {"cvode-projection",
         "cvode-bdf with the method's post-step projection inside CVODE (CVodeSetProjFn, "
         "projected error estimate): no restart after a projection",
         false, 5},
        {"cvode-projection-noerr", "cvode-projection without projecting the error estimate (CVodeSetProjErrEst off)",
         false, 5},
        {"own",
         "the method's own fixed-step scheme, for the methods that step themselves (their description "
         "says --integrator own); off-grid output by a side step of the scheme",
         true, 2, MethodKind::kSelfStepping},
    };
    add_arkode_integrators(l);
    return l;
  }();
  return list;
}

const IntegratorInfo& find_integrator(const std::string& name) {
  for (const auto& i : all_integrators())
    if (i.name == name) return i;
  if (const std::string why = arkode_unknown_table(name); !why.empty()) throw UsageError(why);
  std::string known;
  for (const auto& i : all_integrators()) known += (known.empty() ? "" : ", ") + i.name;
  throw UsageError("--integrator " + name + ": unknown integrator (known: " + known + ")");
}

MethodKind method_kind_of(const Formulation& form) {
  if (dynamic_cast<const DaeSystem*>(&form)) return MethodKind::kDae;
  if (dynamic_cast<const SteppingSystem*>(&form)) return MethodKind::kSelfStepping;
  return MethodKind::kOde;
}

std::string pairing_error(MethodKind method, const std::string& name, const IntegratorInfo& integ) {
  if (method == integ.kind) return "";
  const std::string flag = "--integrator " + integ.name + ": ";
  if (method == MethodKind::kDae)
    return flag + "method '" + name +
           "' is a DAE formulation F(t, y, y') = 0 and needs a DAE integrator (--integrator ida)";
  if (method == MethodKind::kSelfStepping)
    return flag + "method '" + name +
           "' is its own implicit time-stepping scheme and runs only with --integrator own";
  if (integ.kind == MethodKind::kDae)
    return flag + "solves DAEs F(t, y, y') = 0, but method '" + name +
           "' is an ODE formulation; use a DAE method (ida-index1, ida-ggl)";
  return flag + "steps methods that are their own implicit scheme (generalized-alpha, hht, "
                "generalized-alpha-i2), but method '" + name + "' is an ODE formulation; use an ODE integrator";
}

bool Integrator::eval(double t, const double* y, double* dydt) {
  ++rhs_evals_;
  if (!sys_->rhs(t, y, dydt)) {
    failure_ = sys_->failure_reason();
    if (failure_.empty()) failure_ = "right-hand side failed";
    return false;
  }
  return true;
}

namespace {

// Shared fixed-step machinery: grid bookkeeping and the RK4 side step.
class FixedStep : public Integrator {
 public:
  explicit FixedStep(double h) : h_(h) {}

  void start(OdeSystem& sys, double t0, const double* y0) override {
    sys_ = &sys;
    n_ = sys.dimension();
    y_.assign(y0, y0 + n_);
    k1_.assign(n_, 0); k2_.assign(n_, 0); k3_.assign(n_, 0); k4_.assign(n_, 0); tmp_.assign(n_, 0);
    t0_ = t0; t_ = t0; grid_index_ = 0;
    steps_ = rejected_ = rhs_evals_ = 0;
    failure_.clear();
    on_start();
  }

  StepOutcome step(double t_limit) override {
    double t_next = t0_ + double(grid_index_ + 1) * h_;
    if (t_next > t_limit + 1e-9 * h_) return StepOutcome::kPastLimit;
    if (std::abs(t_next - t_limit) <= 1e-9 * h_) t_next = t_limit;  // land exactly on output times
    if (!advance(t_next)) return StepOutcome::kFailed;
    ++grid_index_;
    ++steps_;
    t_ = t_next;
    h_used_ = h_;
    return StepOutcome::kOk;
  }

  bool state_at(double t_target, double* out) override {
    const double dt = t_target - t_;
    if (dt == 0) { std::copy(y_.begin(), y_.end(), out); return true; }
    return rk4(t_, y_.data(), dt, out, /*have_k1=*/false);
  }

 protected:
  virtual void on_start() {}
  // Advance y_ from t_ to t_next (= t_ + h_ up to rounding).
  virtual bool advance(double t_next) = 0;

  // One classical RK4 step of size dt from (t, y) into out (may alias y).
  bool rk4(double t, const double* y, double dt, double* out, bool have_k1) {
    if (!have_k1 && !eval(t, y, k1_.data())) return false;
    for (int i = 0; i < n_; ++i) tmp_[i] = y[i] + 0.5 * dt * k1_[i];
    if (!eval(t + 0.5 * dt, tmp_.data(), k2_.data())) return false;
    for (int i = 0; i < n_; ++i) tmp_[i] = y[i] + 0.5 * dt * k2_[i];
    if (!eval(t + 0.5 * dt, tmp_.data(), k3_.data())) return false;
    for (int i = 0; i < n_; ++i) tmp_[i] = y[i] + dt * k3_[i];
    if (!eval(t + dt, tmp_.data(), k4_.data())) return false;
    for (int i = 0; i < n_; ++i)
      out[i] = y[i] + dt / 6.0 * (k1_[i] + 2 * k2_[i] + 2 * k3_[i] + k4_[i]);
    return true;
  }

  double h_;
  double t0_ = 0;
  long grid_index_ = 0;
  std::vector<double> k1_, k2_, k3_, k4_, tmp_;
};

class Rk4 final : public FixedStep {
 public:
  using FixedStep::FixedStep;
  bool notify_modified() override { return true; }

 private:
  bool advance(double t_next) override {
    (void)t_next;
    return rk4(t_, y_.data(), h_, y_.data(), false);
  }
};

class Euler final : public FixedStep {
 public:
  using FixedStep::FixedStep;
  bool notify_modified() override { return true; }

 private:
  bool advance(double) override {
    if (!eval(t_, y_.data(), k1_.data())) return false;
    for (int i = 0; i < n_; ++i) y_[i] += h_ * k1_[i];
    return true;
  }
};

// Adams-Bashforth 4 predictor, Adams-Moulton 4 (3-step) corrector, evaluating
// f at the corrected point (PECE): two right-hand sides per step.
class AdamsPece final : public FixedStep {
 public:
  using FixedStep::FixedStep;

  bool notify_modified() override {
    // Keep the history, re-evaluate f at the changed current point.
    if (!have_history_) return true;
    return eval(t_, y_.data(), f_[0].data());
  }

 private:
  void on_start() override {
    for (auto& f : f_) f.assign(n_, 0);
    pred_.assign(n_, 0);
    fpred_.assign(n_, 0);
    have_history_ = false;
  }

  bool advance(double t_next) override {
    if (grid_index_ < 3) {
      // Start-up with RK4, recording f at each grid point.
      if (!eval(t_, y_.data(), k1_.data())) return false;
      std::copy(k1_.begin(), k1_.end(), f_[3 - grid_index_].begin());
      // f_[3] = f(t0), f_[2] = f(t1), f_[1] = f(t2), then f_[0] = f(t3).
      if (!rk4(t_, y_.data(), h_, y_.data(), true)) return false;
      if (grid_index_ == 2) {
        if (!eval(t_next, y_.data(), f_[0].data())) return false;
        have_history_ = true;
      }
      return true;
    }
    // f_[0] = f_n, f_[1] = f_{n-1}, f_[2] = f_{n-2}, f_[3] = f_{n-3}.
    const double c = h_ / 24.0;
    for (int i = 0; i < n_; ++i)
      pred_[i] = y_[i] + c * (55 * f_[0][i] - 59 * f_[1][i] + 37 * f_[2][i] - 9 * f_[3][i]);
    if (!eval(t_next, pred_.data(), fpred_.data())) return false;
    for (int i = 0; i < n_; ++i)
      y_[i] += c * (9 * fpred_[i] + 19 * f_[0][i] - 5 * f_[1][i] + f_[2][i]);
    std::rotate(f_.begin(), f_.begin() + 3, f_.end());  // shift history by one
    return eval(t_next, y_.data(), f_[0].data());
  }

  std::array<std::vector<double>, 4> f_;
  std::vector<double> pred_, fpred_;
  bool have_history_ = false;
};

// "own": the fixed grid of FixedStep, each step the method's own scheme
// (SteppingSystem::advance). An output time between grid points is reached
// by a side step of the scheme itself from the last grid point (of size
// t_target - t), which leaves the trajectory on the grid undisturbed.
class OwnScheme final : public FixedStep {
 public:
  using FixedStep::FixedStep;
  bool notify_modified() override { return true; }

  bool state_at(double t_target, double* out) override {
    std::copy(y_.begin(), y_.end(), out);
    const double dt = t_target - t_;
    if (dt == 0) return true;
    if (!ready()) return false;
    const bool ok = scheme_->advance(t_, dt, out);
    if (!ok) failure_ = reason();
    rhs_evals_ = scheme_->evaluations();
    return ok;
  }

  std::vector<std::pair<std::string, std::string>> statistics() const override {
    return scheme_ ? scheme_->statistics() : std::vector<std::pair<std::string, std::string>>{};
  }

 private:
  void on_start() override { scheme_ = dynamic_cast<SteppingSystem*>(sys_); }
  bool ready() {
    if (scheme_) return true;
    failure_ = "own: the method is not its own time-stepping scheme (use an ODE integrator)";
    return false;
  }
  std::string reason() const {
    const std::string& r = sys_->failure_reason();
    return r.empty() ? "the method's step failed" : r;
  }
  bool advance(double t_next) override {
    if (!ready()) return false;
    const bool ok = scheme_->advance(t_, t_next - t_, y_.data());
    rhs_evals_ = scheme_->evaluations();
    if (!ok) failure_ = reason();
    return ok;
  }

  SteppingSystem* scheme_ = nullptr;
};

// What a GSL odeiv2 evolve status means, in words (gsl_strerror alone says
// "failure" for the step-size underflow).
std::string gsl_failure_words(int status, double t, double h) {
  const std::string at = " at t = " + format_short(t);
  switch (status) {
    case GSL_FAILURE:
      return "step-size underflow: no acceptable step above machine precision (last try " + format_short(h) + ")" + at;
    case GSL_EBADFUNC: return "the right-hand side failed" + at;
    case GSL_ENOMEM: return "GSL: out of memory" + at;
    case GSL_EMAXITER: return "GSL: too many iterations (the implicit solve did not converge)" + at;
    case GSL_ENOPROG: return "GSL: no progress (step size at its minimum)" + at;
    default:
      return std::string("GSL: ") + gsl_strerror(status) + " (GSL error " + std::to_string(status) + ")" + at;
  }
}

// GSL odeiv2 adaptive schemes, driven one step at a time via evolve_apply.
class GslAdaptive final : public Integrator {
 public:
  GslAdaptive(const gsl_odeiv2_step_type* type, const StepSettings& s) : type_(type), settings_(s) {}
  ~GslAdaptive() override { release(); }

  void start(OdeSystem& sys, double t0, const double* y0) override {
    release();
    sys_ = &sys;
    n_ = sys.dimension();
    y_.assign(y0, y0 + n_);
    t_ = t0;
    steps_ = rejected_ = rhs_evals_ = 0;
    failure_.clear();
    fd_f0_.assign(n_, 0); fd_f1_.assign(n_, 0); fd_y_.assign(n_, 0);
    jac_.assign(size_t(n_) * n_, 0);
    system_jacobians_ = 0;
    const char* mode = std::getenv("CSTAB_JACOBIAN");
    system_jacobian_ = sys.has_jacobian() && !(mode && std::string(mode) == "dq");
    gsys_ = gsl_odeiv2_system{&GslAdaptive::gsl_rhs, &GslAdaptive::gsl_jac, size_t(n_), this};
    h_ = 1e-6;
    driver_ = gsl_odeiv2_driver_alloc_y_new(&gsys_, type_, h_, settings_.atol, settings_.rtol);
  }

  StepOutcome step(double t_limit) override {
    const double t_before = t_;
    const auto failed_before = driver_->e->failed_steps;
    const int status = gsl_odeiv2_evolve_apply(driver_->e, driver_->c, driver_->s, &gsys_, &t_,
                                               t_limit, &h_, y_.data());
    rejected_ += long(driver_->e->failed_steps - failed_before);
    if (status != GSL_SUCCESS) {
      if (failure_.empty()) failure_ = gsl_failure_words(status, t_, h_);
      return StepOutcome::kFailed;
    }
    h_used_ = t_ - t_before;
    ++steps_;
    if (!(h_used_ > 1e-14 * std::max(1.0, std::abs(t_))) && t_ < t_limit) {
      failure_ = "step-size underflow: step " + format_short(h_used_) + " at t = " + format_short(t_) +
                 " (tolerances too tight, or the solution is not smooth here)";
      return StepOutcome::kFailed;
    }
    return StepOutcome::kOk;
  }

  bool state_at(double t_target, double* out) override {
    if (t_target != t_) return false;
    std::copy(y_.begin(), y_.end(), out);
    return true;
  }

  // The implicit scheme's Jacobian: the system's (dfdt by a forward
  // difference) or difference quotients; system_jacobians counts the first.
  std::vector<std::pair<std::string, std::string>> statistics() const override {
    if (type_ != gsl_odeiv2_step_msbdf) return {};
    return {{"jacobian", system_jacobian_ ? "system" : "dq"},
            {"msbdf_system_jacobians", std::to_string(system_jacobians_)}};
  }

  bool notify_modified() override {
    // Multistep history is invalid after y changed.
    gsl_odeiv2_evolve_reset(driver_->e);
    gsl_odeiv2_step_reset(driver_->s);
    return true;
  }

 private:
  static int gsl_rhs(double t, const double y[], double dydt[], void* self_ptr) {
    auto* self = static_cast<GslAdaptive*>(self_ptr);
    return self->eval(t, y, dydt) ? GSL_SUCCESS : GSL_EBADFUNC;
  }

  // Forward-difference Jacobian for the implicit BDF scheme. For diagnosis,
  // CSTAB_MSBDF_CENTRAL_JACOBIAN=1 in the environment makes it central
  // differences (error O(d^2) instead of O(d)): docs/measurements.md uses it
  // to show that msbdf's cost at high gains does not come from the
  // Jacobian's accuracy.
  static int gsl_jac(double t, const double y[], double* dfdy, double dfdt[], void* self_ptr) {
    auto* self = static_cast<GslAdaptive*>(self_ptr);
    const int n = self->n_;
    if (!self->eval(t, y, self->fd_f0_.data())) return GSL_EBADFUNC;
    std::copy(y, y + n, self->fd_y_.begin());
    static const bool central = std::getenv("CSTAB_MSBDF_CENTRAL_JACOBIAN") != nullptr;
    // The system's own (column-major; GSL's is row-major), where it has one.
    bool have = false;
    if (self->system_jacobian_ && !central) {
      have = self->sys_->jacobian(t, y, self->jac_.data());
      if (have) {
        ++self->system_jacobians_;
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) dfdy[i * n + j] = self->jac_[i + j * n];
      }
    }
    for (int j = 0; j < n && !have; ++j) {
      if (central) {
        const double dy = std::cbrt(2.2e-16) * std::max(1.0, std::abs(y[j]));
        self->fd_y_[j] = y[j] + dy;
        if (!self->eval(t, self->fd_y_.data(), self->fd_f1_.data())) return GSL_EBADFUNC;
        for (int i = 0; i < n; ++i) dfdy[i * n + j] = self->fd_f1_[i];
        self->fd_y_[j] = y[j] - dy;
        if (!self->eval(t, self->fd_y_.data(), self->fd_f1_.data())) return GSL_EBADFUNC;
        for (int i = 0; i < n; ++i) dfdy[i * n + j] = (dfdy[i * n + j] - self->fd_f1_[i]) / (2 * dy);
        self->fd_y_[j] = y[j];
        continue;
      }
      const double dy = std::sqrt(2.2e-16) * std::max(1.0, std::abs(y[j]));
      self->fd_y_[j] = y[j] + dy;
      if (!self->eval(t, self->fd_y_.data(), self->fd_f1_.data())) return GSL_EBADFUNC;
      for (int i = 0; i < n; ++i) dfdy[i * n + j] = (self->fd_f1_[i] - self->fd_f0_[i]) / dy;
      self->fd_y_[j] = y[j];
    }
    const double dt = std::sqrt(2.2e-16) * std::max(1.0, std::abs(t));
    if (!self->eval(t + dt, y, self->fd_f1_.data())) return GSL_EBADFUNC;
    for (int i = 0; i < n; ++i) dfdt[i] = (self->fd_f1_[i] - self->fd_f0_[i]) / dt;
    return GSL_SUCCESS;
  }

  void release() {
    if (driver_) gsl_odeiv2_driver_free(driver_);
    driver_ = nullptr;
  }

  const gsl_odeiv2_step_type* type_;
  StepSettings settings_;
  gsl_odeiv2_system gsys_{};
  gsl_odeiv2_driver* driver_ = nullptr;
  double h_ = 0;
  std::vector<double> fd_f0_, fd_f1_, fd_y_, jac_;
  bool system_jacobian_ = false;  // the system's own Jacobian (CSTAB_JACOBIAN=dq: difference quotients)
  long system_jacobians_ = 0;
};

}  // namespace

std::unique_ptr<Integrator> make_ida_integrator(const StepSettings& settings);  // ida_integrator.cpp
// cvode_integrator.cpp; projection: 0 none, 1 CVodeSetProjFn with the error projected, 2 without
std::unique_ptr<Integrator> make_cvode_integrator(const StepSettings& settings, bool bdf, int projection = 0);
std::unique_ptr<Integrator> make_arkode_integrator(const std::string& name, const StepSettings& settings);

std::unique_ptr<Integrator> make_integrator(const std::string& name, const StepSettings& s) {
  static const bool gsl_quiet = [] { gsl_set_error_handler_off(); return true; }();
  (void)gsl_quiet;
  const auto& info = find_integrator(name);
  if (info.fixed_step) {
    if (!(s.step > 0) || !std::isfinite(s.step))
      throw UsageError("--step: integrator '" + name + "' needs a finite step > 0");
  } else {
    if (!(s.rtol > 0) || !std::isfinite(s.rtol))
      throw UsageError("--rtol: integrator '" + name + "' needs a finite rtol > 0");
    if (!(s.atol > 0) || !std::isfinite(s.atol))
      throw UsageError("--atol: integrator '" + name + "' needs a finite atol > 0");
  }
  if (name == "euler") return std::make_unique<Euler>(s.step);
  if (name == "rk4") return std::make_unique<Rk4>(s.step);
  if (name == "adams") return std::make_unique<AdamsPece>(s.step);
  if (name == "rk8pd") return std::make_unique<GslAdaptive>(gsl_odeiv2_step_rk8pd, s);
  if (name == "rkf45") return std::make_unique<GslAdaptive>(gsl_odeiv2_step_rkf45, s);
  if (name == "msadams") return std::make_unique<GslAdaptive>(gsl_odeiv2_step_msadams, s);
  if (name == "msbdf") return std::make_unique<GslAdaptive>(gsl_odeiv2_step_msbdf, s);
  if (name == "ida") return make_ida_integrator(s);
  if (name == "cvode-bdf") return make_cvode_integrator(s, true);
  if (name == "cvode-adams") return make_cvode_integrator(s, false);
  if (name == "cvode-projection") return make_cvode_integrator(s, true, 1);
  if (name == "cvode-projection-noerr") return make_cvode_integrator(s, true, 2);
  if (auto ark = make_arkode_integrator(name, s)) return ark;
  if (name == "own") return std::make_unique<OwnScheme>(s.step);
  throw UsageError("--integrator " + name + ": not constructible");
}

}  // namespace cstab

// What the implicit schemes that step themselves share
// (methods/generalized_alpha.hpp, methods/ali3p.hpp): the terms of a Newton
// iteration on a mechanical model (M a = Q + A^T lambda), by AD of the model
// functions, and the formulation base that runs with --integrator own and
// counts the iterations.
#pragma once

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/vec.hpp"
#include "methods/mechanical.hpp"

namespace cstab {

// A mechanical formulation that is its own time-stepping scheme (a
// SteppingSystem for --integrator own) with an iteration per step. Summary
// columns: newton_iters (total), newton_conv_fails, newton_max_iters_per_step.
template <class Model>
class SelfSteppingFormulation : public MechanicalFormulationBase<Model>, public SteppingSystem {
 public:
  SelfSteppingFormulation(const Model& model, const char* method)
      : MechanicalFormulationBase<Model>(model), method_(method) {}

  bool rhs(double, const double*, double*) override {
    this->failure_ = std::string(method_) + " is its own implicit time-stepping scheme: it needs --integrator own";
    return false;
  }
  void set_step_hint(double h) override { step_hint_ = h; }
  bool has_condition_number() const override { return step_hint_ > 0; }
  long evaluations() const override { return evaluations_; }
  std::vector<std::pair<std::string, std::string>> statistics() const override {
    return {{"newton_iters", std::to_string(newton_iterations_)},
            {"newton_conv_fails", std::to_string(newton_failures_)},
            {"newton_max_iters_per_step", std::to_string(newton_max_per_step_)}};
  }

 protected:
  // Records one step's iterations and whether they converged.
  void count_step(int iterations, bool converged) {
    newton_iterations_ += iterations;
    newton_max_per_step_ = std::max<long>(newton_max_per_step_, iterations);
    if (!converged) ++newton_failures_;
  }

  const char* method_;
  double step_hint_ = 0;
  long evaluations_ = 0;

 private:
  long newton_iterations_ = 0, newton_failures_ = 0, newton_max_per_step_ = 0;
};

// The names a self-stepping formulation takes from its base (a dependent base).
#define CSTAB_SELF_STEPPING_MEMBERS(Base) \
  CSTAB_MECHANICAL_SIZES(Base);           \
  using Base::method_;                    \
  using Base::step_hint_;                 \
  using Base::evaluations_;               \
  using Base::count_step

template <class Model>
struct NewtonTerms : MechanicalSizes<Model> {
  CSTAB_MECHANICAL_SIZES(MechanicalSizes<Model>);

  Eigen::Matrix<double, nq, nq> M, K, C;
  VecQ r;
  Eigen::Matrix<double, nc, nq> A, Av;
  Vec<double, nc> vel;
  Vec<double, nh> phi;

  // At (t, q, v, vdot, lambda), by AD with the 2 nq directions (q, v):
  // r = M vdot - Q - A^T lambda with K = dr/dq, C = dr/dv; M; Phi; the rows
  // A = [Phi_q; dPsi/dv]; vel = [Phi_q v + Phi_t; Psi] and Av = dvel/dq.
  // The constraint rows inside r are themselves derivatives: a second,
  // inner level of duals on top of the first.
  void evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, const VecQ& vdot,
                const Vec<double, nc>& lambda);
  // Defined below, out of line: a problem instantiates it once for its model
  // (cstab_model in its CMakeLists.txt, CSTAB_EXTERN_MODEL_TEMPLATES in its
  // header: methods/model_templates.hpp), as for MechanicalTerms
  // (docs/build.md).
};

template <class Model>
void NewtonTerms<Model>::evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, const VecQ& vdot,
                                const Vec<double, nc>& lambda) {
  using D = ad::Dual<2 * nq>;
  Vec<D, nq> qd, vd;
  for (int i = 0; i < nq; ++i) {
    qd(i) = D(q(i), 2 * nq, i);
    vd(i) = D(v(i), 2 * nq, nq + i);
  }
  const D td(t);
  Eigen::Matrix<D, nq, nq> Md;
  model.mass(td, qd, Md);
  Vec<D, nq> Qd;
  model.forces(td, qd, vd, Qd);
  Vec<D, nq> rd = Md * vdot.template cast<D>() - Qd;
  Vec<D, nc> veld;
  if constexpr (nh > 0) {
    // Inner duals: the nq positions and time, on top of D.
    using T = Eigen::AutoDiffScalar<Eigen::Matrix<D, nq + 1, 1>>;
    using DerT = Eigen::Matrix<D, nq + 1, 1>;
    Vec<T, nq> qt;
    for (int i = 0; i < nq; ++i) {
      DerT e = DerT::Constant(D(0.0));
      e(i) = D(1.0);
      qt(i) = T(qd(i), e);
    }
    DerT et = DerT::Constant(D(0.0));
    et(nq) = D(1.0);
    const T tt(td, et);
    Vec<T, nh> phit;
    model.holonomic(tt, qt, phit);
    for (int i = 0; i < nh; ++i) {
      D row_v = phit(i).derivatives()(nq);  // Phi_t
      for (int j = 0; j < nq; ++j) {
        const D& dij = phit(i).derivatives()(j);
        rd(j) -= dij * lambda(i);
        row_v += dij * vd(j);
        A(i, j) = dij.value();
      }
      veld(i) = row_v;
      phi(i) = phit(i).value().value();
    }
  }
  if constexpr (nn > 0) {
    // Inner duals: the nq velocities (Psi is affine in v: G = dPsi/dv).
    using T = Eigen::AutoDiffScalar<Eigen::Matrix<D, nq, 1>>;
    using DerT = Eigen::Matrix<D, nq, 1>;
    const DerT zero = DerT::Constant(D(0.0));
    Vec<T, nq> qt, vt;
    for (int i = 0; i < nq; ++i) {
      qt(i) = T(qd(i), zero);
      DerT e = zero;
      e(i) = D(1.0);
      vt(i) = T(vd(i), e);
    }
    const T tt(td, zero);
    Vec<T, nn> psi;
    model.nonholonomic(tt, qt, vt, psi);
    for (int i = 0; i < nn; ++i) {
      for (int j = 0; j < nq; ++j) {
        const D& gij = psi(i).derivatives()(j);
        rd(j) -= gij * lambda(nh + i);
        A(nh + i, j) = gij.value();
      }
      veld(nh + i) = psi(i).value();
    }
  }
  for (int i = 0; i < nq; ++i) {
    r(i) = rd(i).value();
    K.row(i) = rd(i).derivatives().template head<nq>().transpose();
    C.row(i) = rd(i).derivatives().template tail<nq>().transpose();
    for (int j = 0; j < nq; ++j) M(i, j) = Md(i, j).value();
  }
  for (int i = 0; i < nc; ++i) {
    vel(i) = veld(i).value();
    Av.row(i) = veld(i).derivatives().template head<nq>().transpose();
  }
}

}  // namespace cstab

// The bare dynamics with the constraints ignored: a = M^-1 Q for a
// mechanical model, X' = F(X) for an affine one. Not a method (it does not
// solve the problem); the cost baseline the benchmarks compare against.
#pragma once

#include "methods/affine.hpp"
#include "methods/mechanical.hpp"
#include "linalg/small_linalg.hpp"

namespace cstab {

template <class Model>
class UnconstrainedMechanical final : public MechanicalFormulationBase<Model> {
  using Base = MechanicalFormulationBase<Model>;

 public:
  using Base::nq;
  using typename Base::VecQ;
  explicit UnconstrainedMechanical(const Model& model) : Base(model) {}

  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    this->model_.mass(t, q, M_);
    this->model_.forces(t, q, v, Q_);
    if (!mass_.factor(M_)) return false;
    vmap<nq>(dydt) = v;
    vmap<nq>(dydt + nq) = mass_.solve(Q_);
    return true;
  }

 private:
  Eigen::Matrix<double, nq, nq> M_;
  VecQ Q_;
  SmallCholesky<nq> mass_;  // the same factorization code as the methods'

};

template <class Model>
class UnconstrainedAffine final : public AffineFormulationBase<Model> {
 public:
  using AffineFormulationBase<Model>::n;
  explicit UnconstrainedAffine(const Model& model) : AffineFormulationBase<Model>(model) {}
  bool rhs(double t, const double* y, double* dydt) override {
    Vec<double, n> F;
    this->model_.drift(t, vmap<n>(y).eval(), F);
    vmap<n>(dydt) = F;
    return true;
  }
};

}  // namespace cstab

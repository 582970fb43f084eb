// The bare dynamics with the constraints ignored: a = M^-1 Q for a
// mechanical model, X' = F(X) for an affine one. Not a method (it does not
// solve the problem); the cost baseline the benchmarks compare against.
#pragma once

#include "methods/affine.hpp"
#include "methods/mechanical.hpp"

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
    llt_.compute(M_);
    vmap<nq>(dydt) = v;
    vmap<nq>(dydt + nq) = llt_.solve(Q_);
    return true;
  }

 private:
  Eigen::Matrix<double, nq, nq> M_;
  VecQ Q_;
  Eigen::LLT<Eigen::Matrix<double, nq, nq>> llt_;
};

template <class Model>
class UnconstrainedAffine final : public Formulation {
 public:
  static constexpr int n = Model::kStates;
  explicit UnconstrainedAffine(const Model& model) : model_(model), constraints_(model.constraints()) {}
  std::string formulation_name() const override { return model_.formulation_name(); }
  int dimension() const override { return n; }
  void initial_state(double* y) const override {
    Vec<double, n> X;
    model_.initial_state(X);
    vmap<n>(y) = X;
  }
  bool rhs(double t, const double* y, double* dydt) override {
    Vec<double, n> F;
    model_.drift(t, vmap<n>(y).eval(), F);
    vmap<n>(dydt) = F;
    return true;
  }
  const std::vector<ConstraintInfo>& constraints() const override { return constraints_; }
  void residuals(double t, const double* y, double* out) const override {
    Vec<double, Model::kInputs> f;
    model_.outputs(t, vmap<n>(y).eval(), f);
    vmap<Model::kInputs>(out) = f;
  }
  void to_canonical(double t, const double* y, double* c) const override {
    model_.to_canonical(t, vmap<n>(y).eval(), c);
  }

 private:
  Model model_;
  std::vector<ConstraintInfo> constraints_;
};

}  // namespace cstab

// Two deliberately wrong plugin methods for `cstab check` (tests/plugins):
//  * allocating-none: `none` whose right-hand side allocates a vector per call;
//  * ignores-constraints: M a = Q, every constraint row ignored, yet
//    declared (by default) a stabilizing method.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "linalg/small_linalg.hpp"
#include "methods/index1.hpp"

namespace bad {

template <class Model>
class AllocatingNone final : public cstab::IndexOneFormulation<Model> {
  using Base = cstab::IndexOneFormulation<Model>;

 public:
  explicit AllocatingNone(const Model& model) : Base(model, false, 0.0, 0) {}
  bool rhs(double t, const double* y, double* dydt) override {
    scratch_ = std::vector<double>(y, y + this->dimension());  // a heap allocation per call
    return Base::rhs(t, scratch_.data(), dydt);
  }

 private:
  std::vector<double> scratch_;
};

struct AllocatingNoneMethod : cstab::MechanicalMethod<AllocatingNoneMethod> {
  static constexpr const char* kName = "allocating-none";
  static constexpr const char* kDescription = "none, allocating in every right-hand side (a test of cstab check)";
  static cstab::ConformanceSettings conformance() {
    cstab::ConformanceSettings s;
    s.stabilizes = false;
    return s;
  }
  static std::vector<cstab::ParamSpec> generic_params() { return {}; }
  template <class Model>
  static std::unique_ptr<cstab::Formulation> make_model(const Model& model, const cstab::Params&) {
    return std::make_unique<AllocatingNone<Model>>(model);
  }
};

template <class Model>
class IgnoresConstraints final : public cstab::MechanicalFormulationBase<Model> {
  using Base = cstab::MechanicalFormulationBase<Model>;

 public:
  CSTAB_MECHANICAL_SIZES(Base);
  explicit IgnoresConstraints(const Model& model) : Base(model) {}
  bool rhs(double t, const double* y, double* dydt) override {
    const VecQ q = cstab::vmap<nq>(y), v = cstab::vmap<nq>(y + nq);
    terms_.evaluate(this->model_, t, q, v, false);
    if (!mass_.factor(terms_.M)) return false;
    cstab::vmap<nq>(dydt) = v;
    cstab::vmap<nq>(dydt + nq) = mass_.solve(terms_.Q);
    return true;
  }

 private:
  cstab::MechanicalTerms<Model> terms_;
  cstab::SmallCholesky<nq> mass_;
};

struct IgnoresConstraintsMethod : cstab::MechanicalMethod<IgnoresConstraintsMethod> {
  static constexpr const char* kName = "ignores-constraints";
  static constexpr const char* kDescription = "M a = Q, the constraints ignored (a test of cstab check)";
  static std::vector<cstab::ParamSpec> generic_params() { return {}; }
  template <class Model>
  static std::unique_ptr<cstab::Formulation> make_model(const Model& model, const cstab::Params&) {
    return std::make_unique<IgnoresConstraints<Model>>(model);
  }
};

}  // namespace bad

// "minimal": integrate the problem's own minimal-coordinate ODE, in which the
// constraints hold by construction. Nothing to stabilize; this is the
// baseline every stabilization method is compared against (issue 8), and
// the reference formulation for the problem's accuracy checks.
//
// A minimal model provides (contracts::MinimalModel, methods/contracts.hpp):
//   static constexpr int kStates;
//   std::string formulation_name() const;
//   std::vector<ConstraintInfo> constraints() const;
//   void initial_state(Vec<double,kStates>& y) const;
//   bool rhs(double t, const Vec<double,kStates>& y, Vec<double,kStates>& dy) const;
//   void to_canonical(double t, const Vec<double,kStates>& y, double* canonical) const;
//   void residuals(double t, const Vec<double,kStates>& y, double* out) const;
//     (the problem's constraints evaluated on the mapped state: round-off
//     level by construction).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/formulation.hpp"
#include "core/params.hpp"
#include "methods/affine.hpp"
#include "methods/contracts.hpp"

namespace cstab {

template <class Model>
class MinimalFormulation final : public Formulation {
 public:
  static constexpr int n = Model::kStates;
  explicit MinimalFormulation(const Model& model) : model_(model), constraints_(model.constraints()) {}

  std::string formulation_name() const override { return model_.formulation_name(); }
  bool constraints_hold_by_construction() const override { return true; }
  int dimension() const override { return n; }
  void initial_state(double* y) const override {
    Vec<double, n> y0;
    model_.initial_state(y0);
    vmap<n>(y) = y0;
  }
  bool rhs(double t, const double* y, double* dydt) override {
    Vec<double, n> dy;
    model_.rhs(t, Eigen::Map<const Vec<double, n>>(y).eval(), dy);
    vmap<n>(dydt) = dy;
    return true;
  }
  const std::vector<ConstraintInfo>& constraints() const override { return constraints_; }
  void residuals(double t, const double* y, double* out) const override {
    model_.residuals(t, Eigen::Map<const Vec<double, n>>(y).eval(), out);
  }
  void to_canonical(double t, const double* y, double* c) const override {
    model_.to_canonical(t, Eigen::Map<const Vec<double, n>>(y).eval(), c);
  }

 private:
  Model model_;
  std::vector<ConstraintInfo> constraints_;
};

struct MinimalMethod {
  static constexpr const char* kName = "minimal";
  static constexpr const char* kDescription =
      "the problem's minimal-coordinate ODE (constraints hold by construction): the baseline";
  static std::vector<ParamSpec> generic_params() { return {}; }

  template <class P>
  static std::string why_not(const P&) {
    static_assert(contracts::check_problem<P>());
    return contracts::HasMinimal<P> ? "" : "problem has no minimal-coordinate formulation";
  }
  template <class P>
  static std::vector<ParamSpec> params(const P& p, const std::string& formulation) {
    static_assert(contracts::check_problem<P>());
    if constexpr (contracts::HasMinimal<P>) {
      if (!formulation.empty() && formulation != p.minimal().formulation_name())
        throw UsageError("--formulation " + formulation + ": minimal runs on '" +
                         p.minimal().formulation_name() + "'");
    }
    return {};
  }
  template <class P>
  static std::unique_ptr<Formulation> make(const P& p, const std::string& formulation, const Params&) {
    static_assert(contracts::check_problem<P>());
    params(p, formulation);
    if constexpr (contracts::HasMinimal<P>) {
      using Model = std::decay_t<decltype(p.minimal())>;
      return std::make_unique<MinimalFormulation<Model>>(p.minimal());
    } else {
      throw UsageError("minimal: problem has no minimal-coordinate formulation");
    }
  }
};

}  // namespace cstab

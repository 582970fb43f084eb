// Adapts a concrete problem class (problems/<name>/) to the runtime Problem
// interface. Its methods come as a table of PairOps, one per entry of
// all_methods(), each compiled in its own translation unit; a method that
// does not apply says why (why_not), nothing is silently skipped. P must
// satisfy contracts::ProblemClass (methods/contracts.hpp): a broken problem
// or model is a compile error here, before anything else of it is built.
#pragma once

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include "core/problem.hpp"
#include "methods/contracts.hpp"
#include "methods/pair.hpp"
#include "methods/unconstrained.hpp"

namespace cstab {

template <class P>
class ProblemAdapter final : public Problem {
  static_assert(contracts::check_problem<P>());

 public:
  ProblemAdapter(P problem, std::vector<PairOps> pairs)
      : p_(std::move(problem)), info_(p_.info()), pairs_(std::move(pairs)) {
    check_info_against_class();
  }

  const ProblemInfo& info() const override { return info_; }

  std::string why_not(const std::string& method) const override {
    return pair(method).why_not(&p_);
  }

  std::vector<ParamSpec> method_params(const std::string& method,
                                       const std::string& formulation) const override {
    check_applies(method);
    return pair(method).params(&p_, formulation);
  }

  std::unique_ptr<Formulation> make(const std::string& method, const std::string& formulation,
                                    const Params& params) const override {
    check_applies(method);
    return pair(method).make(&p_, formulation, params);
  }

  std::unique_ptr<Formulation> make_unconstrained() const override {
    if constexpr (contracts::HasMechanical<P>) {
      return std::make_unique<UnconstrainedMechanical<std::decay_t<decltype(p_.mechanical())>>>(p_.mechanical());
    } else if constexpr (contracts::HasStateSpace<P>) {
      return std::make_unique<UnconstrainedAffine<std::decay_t<decltype(p_.state_space())>>>(p_.state_space());
    } else {
      return nullptr;
    }
  }

  // The first of the mechanical and the state-space form whose state is the
  // canonical one (checked at a generic state, not assumed from the class).
  std::unique_ptr<Formulation> make_observer() const override {
    std::unique_ptr<Formulation> f;
    if constexpr (contracts::HasMechanical<P>) {
      f = std::make_unique<UnconstrainedMechanical<std::decay_t<decltype(p_.mechanical())>>>(p_.mechanical());
      if (state_is_canonical(*f)) return f;
    }
    if constexpr (contracts::HasStateSpace<P>) {
      f = std::make_unique<UnconstrainedAffine<std::decay_t<decltype(p_.state_space())>>>(p_.state_space());
      if (state_is_canonical(*f)) return f;
    }
    // A runtime-size model's state is (q, v), its canonical coordinates
    // (n-four-bar, fekete): its rows are evaluated at the canonical state.
    if constexpr (contracts::HasScalable<P>) {
      f = make_scalable_formulation(p_.scalable(), {});
      if (state_is_canonical(*f)) return f;
    }
    return nullptr;
  }

  // The optional observables: used when declared with the exact signature
  // (a member of that name with another one does not compile, see above).
  double energy(double t, const double* c) const override {
    if constexpr (contracts::HasEnergy<P>) return p_.energy(t, c);
    return 0;
  }
  void first_integrals(double t, const double* c, double* out) const override {
    if constexpr (contracts::HasFirstIntegrals<P>) p_.first_integrals(t, c, out);
  }
  bool reference(double t, double* c) const override {
    if constexpr (contracts::HasReference<P>) return p_.reference(t, c);
    return false;
  }

  std::vector<ParamSpec> problem_params() const override {
    if constexpr (contracts::HasProblemParams<P>) return p_.problem_params();
    return {};
  }
  std::unique_ptr<Problem> with_params(const Params& params) const override {
    if constexpr (contracts::HasProblemParams<P>)
      return std::make_unique<ProblemAdapter<P>>(p_.with_params(params), pairs_);
    return nullptr;
  }

  const P& concrete() const { return p_; }

 private:
  // The built-in pairs by method index; a plugin's method after them, by
  // this class's type name (the key its plugin registered the pair under).
  const PairOps& pair(const std::string& method) const {
    const int i = method_index(method);
    if (size_t(i) < pairs_.size()) return pairs_[size_t(i)];
    if (const PairOps* ops = plugin_pair(typeid(P).name(), i)) return *ops;
    static const PairOps not_built{
        [](const void*) { return std::string("its plugin was not built for this problem's class"); }, nullptr,
        nullptr};
    return not_built;
  }
  void check_applies(const std::string& method) const {
    const std::string why = why_not(method);
    if (!why.empty()) throw UsageError("--method " + method + ": does not apply to problem '" +
                                       info_.name + "': " + why);
  }

  // True if `f`'s state has the canonical coordinates' size and its
  // to_canonical returns it unchanged: at the initial state moved off it by
  // perturb_initial_state's pattern, so no component is special.
  bool state_is_canonical(const Formulation& f) const {
    const size_t n = info_.coordinates.size();
    if (size_t(f.dimension()) != n) return false;
    std::vector<double> y(n), c(n);
    f.initial_state(y.data());
    for (size_t i = 0; i < n; ++i) y[i] += 0.125 * std::sin(double(i + 1));
    f.to_canonical(0.0, y.data(), c.data());
    return c == y;
  }

  // What info() promises that only run time can compare with the class:
  // without these a problem claiming an energy law but lacking energy()
  // would report max |dE| = 0 for every run.
  void check_info_against_class() const {
    const std::string who = "problem '" + info_.name + "': ";
    if (info_.has_energy && !contracts::HasEnergy<P>)
      throw std::logic_error(who + "info().has_energy is true but the class has no "
                                   "`double energy(double t, const double* canonical) const`");
    if (!info_.first_integrals.empty() && !contracts::HasFirstIntegrals<P>)
      throw std::logic_error(who + "info().first_integrals names " + std::to_string(info_.first_integrals.size()) +
                             " but the class has no `void first_integrals(double t, const double* canonical, "
                             "double* out) const`");
    if (info_.reference_time > 0 && !contracts::HasReference<P>)
      throw std::logic_error(who + "info().reference_time > 0 but the class has no "
                                   "`bool reference(double t, double* canonical) const`");
  }

  P p_;
  ProblemInfo info_;
  std::vector<PairOps> pairs_;
};

// The methods Ms instantiated for P in the calling translation unit, for
// models that live in a test rather than in problems/; the other methods of
// the catalog say they were not instantiated for it.
template <class P, class... Ms>
std::unique_ptr<Problem> adapt_with_methods(P problem) {
  std::vector<PairOps> pairs;
  for (const auto& info : all_methods()) {
    PairOps ops{[](const void*) { return std::string("not instantiated for this model"); }, nullptr, nullptr};
    ((info.name == Ms::kName ? (ops = pair_ops<Ms, P>(), 0) : 0), ...);
    pairs.push_back(ops);
  }
  return std::make_unique<ProblemAdapter<P>>(std::move(problem), std::move(pairs));
}

}  // namespace cstab

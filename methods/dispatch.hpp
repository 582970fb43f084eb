// Adapts a concrete problem class (problems/) to the runtime Problem
// interface by offering it every method in MethodList. A method that does
// not apply says why (why_not); nothing is silently skipped.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "harness/problem.hpp"
#include "methods/registry.hpp"
#include "methods/unconstrained.hpp"

namespace cstab {

template <class... Ms, class F>
void for_each_method(TypeList<Ms...>, F&& f) {
  (f.template operator()<Ms>(), ...);
}

inline const std::vector<MethodInfo>& all_methods() {
  static const std::vector<MethodInfo> list = [] {
    std::vector<MethodInfo> out;
    for_each_method(MethodList{}, [&]<class M>() {
      out.push_back({M::kName, M::kDescription, M::generic_params()});
    });
    return out;
  }();
  return list;
}

inline void check_method_known(const std::string& method) {
  for (const auto& m : all_methods())
    if (m.name == method) return;
  std::string known;
  for (const auto& m : all_methods()) known += (known.empty() ? "" : ", ") + m.name;
  throw UsageError("--method " + method + ": unknown method (known: " + known + ")");
}

template <class P>
class ProblemAdapter final : public Problem {
 public:
  explicit ProblemAdapter(P problem) : p_(std::move(problem)), info_(p_.info()) {}

  const ProblemInfo& info() const override { return info_; }

  std::string why_not(const std::string& method) const override {
    check_method_known(method);
    std::string why;
    for_each_method(MethodList{}, [&]<class M>() {
      if (method == M::kName) why = M::why_not(p_);
    });
    return why;
  }

  std::vector<ParamSpec> method_params(const std::string& method,
                                       const std::string& formulation) const override {
    check_applies(method);
    std::vector<ParamSpec> specs;
    for_each_method(MethodList{}, [&]<class M>() {
      if (method == M::kName) specs = M::params(p_, formulation);
    });
    return specs;
  }

  std::unique_ptr<Formulation> make(const std::string& method, const std::string& formulation,
                                    const Params& params) const override {
    check_applies(method);
    std::unique_ptr<Formulation> f;
    for_each_method(MethodList{}, [&]<class M>() {
      if (method == M::kName) f = M::make(p_, formulation, params);
    });
    return f;
  }

  std::unique_ptr<Formulation> make_unconstrained() const override {
    if constexpr (HasMechanical<P>) {
      return std::make_unique<UnconstrainedMechanical<std::decay_t<decltype(p_.mechanical())>>>(p_.mechanical());
    } else if constexpr (requires { p_.state_space(); }) {
      return std::make_unique<UnconstrainedAffine<std::decay_t<decltype(p_.state_space())>>>(p_.state_space());
    } else {
      return nullptr;
    }
  }

  double energy(double t, const double* c) const override {
    if constexpr (requires { p_.energy(t, c); }) return p_.energy(t, c);
    return 0;
  }
  void first_integrals(double t, const double* c, double* out) const override {
    if constexpr (requires { p_.first_integrals(t, c, out); }) p_.first_integrals(t, c, out);
  }
  bool reference(double t, double* c) const override {
    if constexpr (requires { p_.reference(t, c); }) return p_.reference(t, c);
    return false;
  }

  const P& concrete() const { return p_; }

 private:
  void check_applies(const std::string& method) const {
    const std::string why = why_not(method);
    if (!why.empty()) throw UsageError("--method " + method + ": does not apply to problem '" +
                                       info_.name + "': " + why);
  }

  P p_;
  ProblemInfo info_;
};

}  // namespace cstab

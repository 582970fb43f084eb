// One problem x method pair behind three plain function pointers. Each pair
// is instantiated once, in a translation unit of its own that the build
// generates (cmake/cstab_catalog.cmake): the build grows with the sum of
// methods and problems, and touching a method recompiles only its pairs.
//
// A method type M provides (contracts::MethodType / MethodFor in
// methods/contracts.hpp; see docs/extending.md):
//   static constexpr const char* kName, kDescription;
//   static std::vector<ParamSpec> generic_params();   // gains declare their ParamRole
//   static constexpr bool kIsDae;                       // optional, default false (MethodKind::kDae)
//   static constexpr MethodKind kKind;                  // optional, default kOde (or kDae by kIsDae)
//   static ConformanceSettings conformance();           // optional, defaults in core/problem.hpp
//   template <class P> static std::string why_not(const P&);          // "" = applies
//   template <class P> static std::vector<ParamSpec> params(const P&, const std::string& formulation);
//   template <class P> static std::unique_ptr<Formulation> make(const P&, const std::string& formulation,
//                                                              const Params&);
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/problem.hpp"

namespace cstab {

// The contract checks (methods/contracts.hpp). Declared here so that this
// header stays light for cli/; every method header includes their
// definitions, and pair_ops / method_info are only instantiated after one.
namespace contracts {
template <class M, class P>
constexpr bool check_pair();
template <class M, class P>
constexpr bool pair_ok();
template <class M>
constexpr bool check_method();
template <class M>
constexpr bool method_ok();
}  // namespace contracts

struct PairOps {
  std::string (*why_not)(const void* problem);
  std::vector<ParamSpec> (*params)(const void* problem, const std::string& formulation);
  std::unique_ptr<Formulation> (*make)(const void* problem, const std::string& formulation, const Params& params);
};

// The contracts are checked first: a broken problem or method is a list of
// one-line static_asserts, and nothing of the pair is instantiated.
template <class M, class P>
PairOps pair_ops() {
  static_assert(contracts::check_pair<M, P>());
  if constexpr (contracts::pair_ok<M, P>()) {
    return {
        [](const void* p) { return M::why_not(*static_cast<const P*>(p)); },
        [](const void* p, const std::string& f) { return M::params(*static_cast<const P*>(p), f); },
        [](const void* p, const std::string& f, const Params& prm) {
          return M::make(*static_cast<const P*>(p), f, prm);
        },
    };
  } else {
    return {nullptr, nullptr, nullptr};
  }
}

template <class M>
MethodInfo method_info() {
  static_assert(contracts::check_method<M>());
  if constexpr (contracts::method_ok<M>()) {
    MethodInfo info{M::kName, M::kDescription, M::generic_params()};
    if constexpr (requires { M::kIsDae; }) info.kind = M::kIsDae ? MethodKind::kDae : MethodKind::kOde;
    if constexpr (requires { M::kKind; }) info.kind = M::kKind;
    if constexpr (requires { M::conformance(); }) info.conformance = M::conformance();
    return info;
  } else {
    return {};
  }
}

// The methods in the build, in the catalog's order (generated).
const std::vector<MethodInfo>& all_methods();
// Index of `method` in all_methods(); throws UsageError naming the known ones.
int method_index(const std::string& method);
inline void check_method_known(const std::string& method) { (void)method_index(method); }

}  // namespace cstab

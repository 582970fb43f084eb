// One problem x method pair behind three plain function pointers. Each pair
// is instantiated once, in a translation unit of its own that the build
// generates (cmake/cstab_catalog.cmake): the build grows with the sum of
// methods and problems, and touching a method recompiles only its pairs.
//
// A method type M provides (see docs/extending.md):
//   static constexpr const char* kName, kDescription;
//   static std::vector<ParamSpec> generic_params();   // gains declare their ParamRole
//   static constexpr bool kIsDae;                       // optional, default false
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

struct PairOps {
  std::string (*why_not)(const void* problem);
  std::vector<ParamSpec> (*params)(const void* problem, const std::string& formulation);
  std::unique_ptr<Formulation> (*make)(const void* problem, const std::string& formulation, const Params& params);
};

template <class M, class P>
PairOps pair_ops() {
  return {
      [](const void* p) { return M::why_not(*static_cast<const P*>(p)); },
      [](const void* p, const std::string& f) { return M::params(*static_cast<const P*>(p), f); },
      [](const void* p, const std::string& f, const Params& prm) {
        return M::make(*static_cast<const P*>(p), f, prm);
      },
  };
}

template <class M>
MethodInfo method_info() {
  MethodInfo info{M::kName, M::kDescription, M::generic_params()};
  if constexpr (requires { M::kIsDae; }) info.is_dae = M::kIsDae;
  if constexpr (requires { M::conformance(); }) info.conformance = M::conformance();
  return info;
}

// The methods in the build, in the catalog's order (generated).
const std::vector<MethodInfo>& all_methods();
// Index of `method` in all_methods(); throws UsageError naming the known ones.
int method_index(const std::string& method);
inline void check_method_known(const std::string& method) { (void)method_index(method); }

}  // namespace cstab

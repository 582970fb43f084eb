// A method type without kName (here misspelled kname).
#include "methods/mechanical_method.hpp"
#include "methods/pair.hpp"
#include "methods/unconstrained.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct NamelessMethod : MechanicalMethod<NamelessMethod> {
  static constexpr const char* kname = "nameless";
  static constexpr const char* kDescription = "the bare dynamics";
  static std::vector<ParamSpec> generic_params() { return {}; }
  template <class Model>
  static std::unique_ptr<Formulation> make_model(const Model& model, const Params&) {
    return std::make_unique<UnconstrainedMechanical<Model>>(model);
  }
};

MethodInfo info() { return method_info<NamelessMethod>(); }
PairOps pair() { return pair_ops<NamelessMethod, Pendulum>(); }

}  // namespace cstab::compile_fail

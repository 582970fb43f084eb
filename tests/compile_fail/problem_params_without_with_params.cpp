// A problem that declares parameters but no way to build the problem with
// other values: `--problem-param` would be accepted and then ignored.
#include "methods/baumgarte.hpp"
#include "methods/problem_adapter.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct ParamsOnly : Pendulum {
  std::vector<ParamSpec> problem_params() const { return {ranged_param("length", 1, 0.1, 10, "rod length")}; }
};

std::unique_ptr<Problem> adapt() { return adapt_with_methods<ParamsOnly, BaumgarteMethod>(ParamsOnly{}); }

}  // namespace cstab::compile_fail

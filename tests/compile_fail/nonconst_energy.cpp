// A problem whose energy() is not const: ProblemAdapter's `p.energy(t, c)`
// on a const problem does not compile, and before the contracts the energy
// was silently 0 (max |dE| = 0).
#include "methods/baumgarte.hpp"
#include "methods/problem_adapter.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct NonConstEnergy : Pendulum {
  double energy(double, const double* c) { return 0.5 * (c[2] * c[2] + c[3] * c[3]) + 9.81 * c[1]; }
};

std::unique_ptr<Problem> adapt() { return adapt_with_methods<NonConstEnergy, BaumgarteMethod>(NonConstEnergy{}); }

}  // namespace cstab::compile_fail

// Instantiates every method for Wheel in a translation unit of its own, so
// problems compile in parallel and a heavy one does not hold up the rest.
#include "methods/dispatch.hpp"
#include "problems/wheel.hpp"

namespace cstab {

std::unique_ptr<Problem> make_wheel_problem() { return std::make_unique<ProblemAdapter<Wheel>>(Wheel{}); }

}  // namespace cstab

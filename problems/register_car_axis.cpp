// Instantiates every method for CarAxis in a translation unit of its own, so
// problems compile in parallel and a heavy one does not hold up the rest.
#include "methods/dispatch.hpp"
#include "problems/car_axis.hpp"

namespace cstab {

std::unique_ptr<Problem> make_car_axis_problem() { return std::make_unique<ProblemAdapter<CarAxis>>(CarAxis{}); }

}  // namespace cstab

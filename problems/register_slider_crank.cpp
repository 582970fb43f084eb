// Instantiates every method for SliderCrank in a translation unit of its own, so
// problems compile in parallel and a heavy one does not hold up the rest.
#include "methods/dispatch.hpp"
#include "problems/slider_crank.hpp"

namespace cstab {

std::unique_ptr<Problem> make_slider_crank_problem() { return std::make_unique<ProblemAdapter<SliderCrank>>(SliderCrank{}); }

}  // namespace cstab

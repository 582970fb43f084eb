// Instantiates every method for Ball in a translation unit of its own, so
// problems compile in parallel and a heavy one does not hold up the rest.
#include "methods/dispatch.hpp"
#include "problems/ball.hpp"

namespace cstab {

std::unique_ptr<Problem> make_ball_problem() { return std::make_unique<ProblemAdapter<Ball>>(Ball{}); }

}  // namespace cstab

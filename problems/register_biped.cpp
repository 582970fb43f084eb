// Instantiates every method for Biped in a translation unit of its own, so
// problems compile in parallel and a heavy one does not hold up the rest.
#include "methods/dispatch.hpp"
#include "problems/biped.hpp"

namespace cstab {

std::unique_ptr<Problem> make_biped_problem() { return std::make_unique<ProblemAdapter<Biped>>(Biped{}); }

}  // namespace cstab

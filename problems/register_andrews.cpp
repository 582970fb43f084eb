// Instantiates every method for Andrews in a translation unit of its own, so
// problems compile in parallel and a heavy one does not hold up the rest.
#include "methods/dispatch.hpp"
#include "problems/andrews.hpp"

namespace cstab {

std::unique_ptr<Problem> make_andrews_problem() { return std::make_unique<ProblemAdapter<Andrews>>(Andrews{}); }

}  // namespace cstab

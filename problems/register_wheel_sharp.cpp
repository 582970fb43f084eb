// Instantiates every method for WheelSharp in a translation unit of its own.
#include "methods/dispatch.hpp"
#include "problems/wheel_sharp.hpp"

namespace cstab {

std::unique_ptr<Problem> make_wheel_sharp_problem() {
  return std::make_unique<ProblemAdapter<WheelSharp>>(WheelSharp{});
}

}  // namespace cstab

// A problem whose mechanical() is not const: before the contracts every
// mechanical method said "problem has no mechanical model" at run time.
#include "methods/baumgarte.hpp"
#include "methods/pair.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct NonConstAccessor : Pendulum {
  const PendulumModel& mechanical() { return model_; }
  PendulumModel model_;
};

PairOps pair() { return pair_ops<BaumgarteMethod, NonConstAccessor>(); }

}  // namespace cstab::compile_fail

// kHasEnergy = true but the energy law has the wrong parameters (q only).
#include "methods/baumgarte.hpp"
#include "methods/pair.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct WrongEnergy : PendulumModel {
  template <class S>
  S energy(const S&, const Vec<S, 2>& q) const {
    return 9.81 * q(1);
  }
};
struct Problem_ : Pendulum {
  const WrongEnergy& mechanical() const { return model_; }
  WrongEnergy model_;
};

PairOps pair() { return pair_ops<BaumgarteMethod, Problem_>(); }

}  // namespace cstab::compile_fail

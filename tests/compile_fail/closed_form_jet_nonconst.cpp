// An affine model whose closed_form_jet is not const: LieJet's call on a
// const model does not match, and before the contracts the jet silently
// came from nested AD.
#include "methods/pesterev.hpp"
#include "methods/pair.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct NonConstJet : PendulumStateSpace {
  template <class Jet>
  void closed_form_jet(double t, const Vec<double, 4>& X, Jet& jet) {
    jet.evaluate_ad(*this, t, X);
  }
};
struct Problem_ : Pendulum {
  const NonConstJet& state_space() const { return ss_; }
  NonConstJet ss_;
};

PairOps pair() { return pair_ops<PesterevMethod, Problem_>(); }

}  // namespace cstab::compile_fail

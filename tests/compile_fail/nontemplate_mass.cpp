// mass written for double only: methods call it with AD scalars too. The
// contract's message must come first, before (and instead of) the errors
// from inside Eigen's AutoDiffScalar.
#include "methods/baumgarte.hpp"
#include "methods/pair.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct DoubleOnlyMass : PendulumModel {
  void mass(double, const Vec<double, 2>&, Eigen::Matrix<double, 2, 2>& M) const { M.setIdentity(); }
};
struct Problem_ : Pendulum {
  const DoubleOnlyMass& mechanical() const { return model_; }
  DoubleOnlyMass model_;
};

PairOps pair() { return pair_ops<BaumgarteMethod, Problem_>(); }

}  // namespace cstab::compile_fail

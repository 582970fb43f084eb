// holonomic written for double only, adapted as test-local models are
// (adapt_with_every_method: ProblemAdapter and every method of the build).
// Before the contracts: two errors from inside MechanicalTerms' hyper-dual
// and dual evaluations (40 lines of AutoDiffScalar types); now one line.
#include "cstab/every_method.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct DoubleOnlyRows : PendulumModel {
  void holonomic(double, const Vec<double, 2>& q, Vec<double, 1>& phi) const { phi(0) = q.squaredNorm() - 1.0; }
};
struct Problem_ : Pendulum {
  const DoubleOnlyRows& mechanical() const { return model_; }
  DoubleOnlyRows model_;
};

std::unique_ptr<Problem> adapt() { return adapt_with_every_method(Problem_{}); }

}  // namespace cstab::compile_fail

// closed_form_holonomic with v taken by reference instead of by pointer:
// MechanicalTerms' exact call does not match, and before the contracts the
// closed form was silently replaced by AD.
#include "methods/baumgarte.hpp"
#include "methods/pair.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

struct MistypedClosedForm : PendulumModel {
  template <class Terms>
  void closed_form_holonomic(double, const Vec<double, 2>& q, const Vec<double, 2>& v, Terms& terms) const {
    terms.phi(0) = q.squaredNorm() - 1.0;
    terms.A.row(0) = 2 * q.transpose();
    terms.phi_t(0) = 0;
    terms.gamma(0) = 2 * v.squaredNorm();
  }
};
struct Problem_ : Pendulum {
  const MistypedClosedForm& mechanical() const { return model_; }
  MistypedClosedForm model_;
};

// As a generated pair unit (build/.../generated/pairs/*.cpp) does.
PairOps pair() { return pair_ops<BaumgarteMethod, Problem_>(); }

}  // namespace cstab::compile_fail

// Control: the correct pendulum compiles through every entry point the
// other tests break (the generated pair units' pair_ops, adapt_with_methods,
// MechanicalTerms, LieJet), so a failure of theirs is the contract's.
#include "methods/baumgarte.hpp"
#include "methods/minimal.hpp"
#include "methods/pesterev.hpp"
#include "methods/problem_adapter.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {

static_assert(contracts::ProblemClass<Pendulum>);
static_assert(contracts::MechanicalModel<PendulumModel>);
static_assert(contracts::MinimalModel<PendulumMinimal>);
static_assert(contracts::AffineModel<PendulumStateSpace>);
static_assert(contracts::MethodFor<BaumgarteMethod, Pendulum> && contracts::MethodFor<PesterevMethod, Pendulum>);
static_assert(MechanicalTerms<PendulumModel>::has_closed_form());
static_assert(LieJet<PendulumStateSpace>::has_closed_form());

PairOps control_pair() { return pair_ops<BaumgarteMethod, Pendulum>(); }
std::unique_ptr<Problem> control_adapt() {
  return adapt_with_methods<Pendulum, BaumgarteMethod, PesterevMethod, MinimalMethod>(Pendulum{});
}

}  // namespace cstab::compile_fail

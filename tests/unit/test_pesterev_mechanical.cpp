// pesterev on a mechanical model runs through a direct fast path
// (A M^-1 A^T N = -phi, methods/pesterev.hpp). Check it against the generic
// route: the mechanical model mapped to the affine form (MechanicalAsAffine)
// with every Lie derivative from nested AD (LieJet).
#include <gtest/gtest.h>

#include "methods/mechanical_affine.hpp"
#include "methods/pesterev.hpp"
#include "problems/wheel/wheel.hpp"

namespace cstab {
namespace {

TEST(PesterevMechanical, FastPathEqualsGenericAffineRoute) {
  const Wheel wheel;
  const WheelMechanical& mech = wheel.mechanical();
  const MechanicalAsAffine<WheelMechanical> affine(mech);
  const std::vector<ParamSpec> specs = {{"lambda", 1500, Bound::kPositive, ""},
                                        {"lambda_distance", 0, Bound::kNonNegative, ""},
                                        {"lambda_rolling", 0, Bound::kNonNegative, ""}};
  const Params params = Params::resolve(specs, {{"lambda", "37"}, {"lambda_rolling", "11"}}, "pesterev");
  PesterevMechanicalFormulation<WheelMechanical> fast(mech, params);
  PesterevFormulation<MechanicalAsAffine<WheelMechanical>> generic(affine, params);
  ASSERT_EQ(fast.dimension(), generic.dimension());

  std::vector<double> y(8), f1(8), f2(8);
  fast.initial_state(y.data());
  // On the manifold and off it (both constraints violated).
  for (double off : {0.0, 1e-3, 2e-2}) {
    std::vector<double> z = y;
    z[0] += off;        // x
    z[1] -= 0.5 * off;  // z
    z[4] += 3 * off;    // xdot
    z[6] -= off;        // thetadot
    ASSERT_TRUE(fast.rhs(0.3, z.data(), f1.data()));
    ASSERT_TRUE(generic.rhs(0.3, z.data(), f2.data()));
    for (int i = 0; i < 8; ++i) EXPECT_NEAR(f1[i], f2[i], 1e-9 * (1 + std::abs(f2[i]))) << "component " << i << ", offset " << off;
    EXPECT_NEAR(fast.condition_number(0.3, z.data()), generic.condition_number(0.3, z.data()),
                1e-8 * generic.condition_number(0.3, z.data()));
  }
}

}  // namespace
}  // namespace cstab

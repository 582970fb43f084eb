// The run-time half of the problem contract: what info() promises is
// compared with what the class declares when ProblemAdapter is built (a
// problem claiming an energy law without energy() reported max |dE| = 0).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "methods/baumgarte.hpp"
#include "methods/problem_adapter.hpp"
#include "tests/compile_fail/pendulum.hpp"

namespace cstab::compile_fail {
namespace {

// The pendulum without its optional observables.
class Bare {
 public:
  explicit Bare(ProblemInfo info) : info_(std::move(info)) {}
  ProblemInfo info() const { return info_; }
  const PendulumModel& mechanical() const { return model_; }

 private:
  ProblemInfo info_;
  PendulumModel model_;
};

ProblemInfo bare_info() {
  ProblemInfo i = Pendulum{}.info();
  i.has_energy = false;
  return i;
}

std::string adapt_error(const ProblemInfo& info) {
  try {
    adapt_with_methods<Bare, BaumgarteMethod>(Bare(info));
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "";
}

TEST(ProblemInfoContract, ConsistentInfoAdapts) {
  EXPECT_EQ(adapt_error(bare_info()), "");
  const auto p = adapt_with_methods<Pendulum, BaumgarteMethod>(Pendulum{});
  const double c[4] = {0.0, -1.0, 1.0, 0.0};
  EXPECT_DOUBLE_EQ(p->energy(0, c), 0.5 - 9.81);  // Pendulum::energy, not the default 0
}

TEST(ProblemInfoContract, EnergyLawWithoutEnergyIsAnError) {
  ProblemInfo info = bare_info();
  info.has_energy = true;
  EXPECT_EQ(adapt_error(info),
            "problem 'compile-fail-pendulum': info().has_energy is true but the class has no "
            "`double energy(double t, const double* canonical) const`");
}

TEST(ProblemInfoContract, FirstIntegralsWithoutTheFunctionAreAnError) {
  ProblemInfo info = bare_info();
  info.first_integrals = {"spin"};
  EXPECT_NE(adapt_error(info).find("info().first_integrals names 1 but the class has no `void first_integrals("),
            std::string::npos);
}

TEST(ProblemInfoContract, ReferenceTimeWithoutReferenceIsAnError) {
  ProblemInfo info = bare_info();
  info.reference_time = 1;
  EXPECT_NE(adapt_error(info).find("info().reference_time > 0 but the class has no `bool reference("),
            std::string::npos);
}

}  // namespace
}  // namespace cstab::compile_fail

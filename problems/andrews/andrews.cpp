#include "problems/andrews/andrews.hpp"

#include <algorithm>
#include <limits>

namespace cstab {

std::vector<ConstraintInfo> AndrewsMechanical::constraints() {
  return {
      {"g1", "holonomic", "x of point F via the crank minus x via the rod from B (Test Set g1)"},
      {"g2", "holonomic", "y of point F via the crank minus y via the rod from B (g2)"},
      {"g3", "holonomic", "x of F via the crank minus x via the lower triangle from A (g3)"},
      {"g4", "holonomic", "y of F via the crank minus y via the lower triangle from A (g4)"},
      {"g5", "holonomic", "x of F via the crank minus x via the upper triangle from A (g5)"},
      {"g6", "holonomic", "y of F via the crank minus y via the upper triangle from A (g6)"},
  };
}

void AndrewsMechanical::initial_state(Vec<double, 7>& q, Vec<double, 7>& v) const {
  // The Test Set's consistent initial values (y1..y7; velocities zero).
  q << -0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
      0.222668390165885884674473185609, 0.487364979543842550225598953530,
      -0.222668390165885884674473185609, 1.23054744454982119249735015568;
  v.setZero();
}

ProblemInfo Andrews::info() const {
  ProblemInfo info;
  info.name = "andrews";
  info.description =
      "Andrews' squeezing mechanism, IVP Test Set (Bari) 'andrews': 7 rigid bodies, 6 loop constraints, "
      "index 3, driving torque and spring";
  info.coordinates = {"beta",     "Theta",     "gamma",     "Phi",     "delta",     "Omega",     "epsilon",
                      "betadot", "Thetadot", "gammadot", "Phidot", "deltadot", "Omegadot", "epsilondot"};
  info.formulations = {
      {"mechanical", "the Test Set's 7 angles, M(q), forces f(q, w), constraints g1..g6",
       AndrewsMechanical::constraints()},
  };
  info.has_energy = true;
  info.default_t_end = 0.03;
  info.reference_time = kReferenceTime;
  info.reference_description =
      "IVP Test Set published solution at t = 0.03 (PSIDE, rtol = atol = 1e-14, Cray double precision); "
      "scored on the 7 angles as the Test Set scores it (rates unscored, NaN: published to ~8 digits only)";
  return info;
}

double Andrews::energy(double t, const double* c) const {
  Vec<double, 7> q, w;
  for (int i = 0; i < 7; ++i) {
    q(i) = c[i];
    w(i) = c[7 + i];
  }
  return mechanical_.energy(t, q, w);
}

const std::array<double, 14>& Andrews::published_reference() {
  // Test Set andrews.f, subroutine solut: y(1..14) at t = 0.03.
  static const std::array<double, 14> ref = {
      0.1581077119629904e+2,  -0.1575637105984298e+2, 0.4082224013073101e-1, -0.5347301163226948e+0,
      0.5244099658805304e+0,  0.5347301163226948e+0,  0.1048080741042263e+1, 0.1139920302151208e+4,
      -0.1424379294994111e+4, 0.1103291221937134e+2,  0.1929337464421385e+2, 0.5735699284790808e+0,
      -0.1929337464421385e+2, 0.3231791658026955e+0,
  };
  return ref;
}

bool Andrews::reference(double t, double* canonical) const {
  if (std::abs(t - kReferenceTime) > 1e-15) return false;
  // Scored: the 7 angles, as the Test Set scores this problem (its drivers
  // skip components > 7 in the scd). The rates are left NaN - unscored: the
  // published rates are accurate to about 8 digits only (they violate the
  // velocity constraint G(q) w = 0 of the published angles by ~6e-10, and
  // the dependent rates follow from betadot only to ~3e-8), while the angles
  // agree with converged cstab solutions to ~1e-10. published_reference()
  // keeps all 14 values for comparisons.
  const auto& ref = published_reference();
  std::copy(ref.begin(), ref.begin() + 7, canonical);
  std::fill(canonical + 7, canonical + 14, std::numeric_limits<double>::quiet_NaN());
  return true;
}

}  // namespace cstab

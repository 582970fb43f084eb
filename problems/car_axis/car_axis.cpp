#include "problems/car_axis/car_axis.hpp"

namespace cstab {

ProblemInfo CarAxis::info() const {
  ProblemInfo info;
  info.name = "car-axis";
  info.description =
      "car axis, IVP Test Set (Bari) 'caraxis': two wheel points joined by an axle, springs, a road bump "
      "yb = r sin(w t); index 3, time-dependent constraint";
  info.coordinates = {"xl", "yl", "xr", "yr", "xldot", "yldot", "xrdot", "yrdot"};
  info.formulations = {
      {"mechanical", "q = (xl, yl, xr, yr), M = k I (k = M eps^2 / 2), springs, gravity, 2 constraints",
       CarAxisMechanical::constraints()},
  };
  info.has_energy = false;
  info.default_t_end = 3;
  info.reference_time = kReferenceTime;
  info.reference_description = "IVP Test Set published solution at t = 3, positions and velocities";
  return info;
}

const std::array<double, 8>& CarAxis::published_reference() {
  // Test Set caraxis.f, subroutine solut: y(1..8) at t = 3.
  static const std::array<double, 8> ref = {
      0.4934557842755629e-001,  0.4969894602303324e+000, 0.1041742524885400e+001, 0.3739110272652214e+000,
      -0.7705836840321485e-001, 0.7446866596327776e-002, 0.1755681574942899e-001, 0.7703410437794031e+000,
  };
  return ref;
}

bool CarAxis::reference(double t, double* canonical) const {
  if (std::abs(t - kReferenceTime) > 1e-12) return false;
  const auto& ref = published_reference();
  std::copy(ref.begin(), ref.end(), canonical);
  return true;
}

}  // namespace cstab

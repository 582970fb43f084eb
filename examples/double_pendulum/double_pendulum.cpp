#include "double_pendulum.hpp"

#include <cmath>

namespace example {

void DoublePendulumCartesian::initial_state(Vec<double, 4>& q, Vec<double, 4>& v) const {
  const double x1 = p_.l1 * std::sin(p_.theta1), y1 = -p_.l1 * std::cos(p_.theta1);
  q << x1, y1, x1 + p_.l2 * std::sin(p_.theta2), y1 - p_.l2 * std::cos(p_.theta2);
  v.setZero();
}

// The textbook equations of the double pendulum in its rod angles (from the
// Lagrangian of two point masses), written with d = theta1 - theta2.
void DoublePendulumAngles::rhs(double, const Vec<double, 4>& y, Vec<double, 4>& dy) const {
  const double m1 = p_.m1, m2 = p_.m2, l1 = p_.l1, l2 = p_.l2, g = p_.g;
  const double t1 = y(0), t2 = y(1), w1 = y(2), w2 = y(3), d = t1 - t2;
  const double den = 2 * m1 + m2 - m2 * std::cos(2 * d);
  dy(0) = w1;
  dy(1) = w2;
  dy(2) = (-g * (2 * m1 + m2) * std::sin(t1) - m2 * g * std::sin(t1 - 2 * t2) -
           2 * std::sin(d) * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * std::cos(d))) /
          (l1 * den);
  dy(3) = 2 * std::sin(d) * (w1 * w1 * l1 * (m1 + m2) + g * (m1 + m2) * std::cos(t1) + w2 * w2 * l2 * m2 * std::cos(d)) /
          (l2 * den);
}

void DoublePendulumAngles::to_canonical(double, const Vec<double, 4>& y, double* c) const {
  const double s1 = std::sin(y(0)), c1 = std::cos(y(0)), s2 = std::sin(y(1)), c2 = std::cos(y(1));
  c[0] = p_.l1 * s1;
  c[1] = -p_.l1 * c1;
  c[2] = c[0] + p_.l2 * s2;
  c[3] = c[1] - p_.l2 * c2;
  c[4] = p_.l1 * c1 * y(2);
  c[5] = p_.l1 * s1 * y(2);
  c[6] = c[4] + p_.l2 * c2 * y(3);
  c[7] = c[5] + p_.l2 * s2 * y(3);
}

cstab::ProblemInfo DoublePendulum::info() const {
  cstab::ProblemInfo i;
  i.name = "double-pendulum";
  i.description = "planar double pendulum in Cartesian coordinates, two point masses on rods (example plugin)";
  i.coordinates = {"x1", "y1", "x2", "y2", "x1dot", "y1dot", "x2dot", "y2dot"};
  i.formulations = {{"mechanical", "q = (x1, y1, x2, y2), constant M, two rod-length constraints",
                     model_.constraints()}};
  i.has_energy = true;
  i.default_t_end = 5;
  i.reference_time = 5;
  i.reference_description = "the rod angles' ODE, GSL rk8pd, rtol = atol = 1e-13";
  return i;
}

double DoublePendulum::energy(double, const double* c) const {
  return 0.5 * p_.m1 * (c[4] * c[4] + c[5] * c[5]) + 0.5 * p_.m2 * (c[6] * c[6] + c[7] * c[7]) +
         p_.g * (p_.m1 * c[1] + p_.m2 * c[3]);
}

}  // namespace example

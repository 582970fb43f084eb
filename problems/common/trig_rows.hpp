// Closed-form derivatives of holonomic rows built from constants, linear
// terms and K cos(theta) / K sin(theta) with theta = q_i or q_i + q_j: the
// value, the Jacobian row and the second derivative along q + s v
// (d^2/ds^2 K cos(theta) = -K cos(theta) theta'^2, theta' = dtheta/dq v).
// Models use it for closed_form_holonomic (methods/mechanical.hpp), which
// tests/unit/test_closed_forms.cpp checks against AD.
#pragma once

#include <Eigen/Dense>
#include <cmath>

namespace cstab {

template <int NQ, int NH>
class TrigRows {
 public:
  struct Angle {
    double c, s, rate;
    int i, j;
  };

  TrigRows(const Eigen::Matrix<double, NQ, 1>& q, const Eigen::Matrix<double, NQ, 1>* v) : q_(q), v_(v) {}

  // theta = q_i (+ q_j if j >= 0)
  Angle angle(int i, int j = -1) const {
    const double th = j >= 0 ? q_(i) + q_(j) : q_(i);
    const double rate = v_ ? (j >= 0 ? (*v_)(i) + (*v_)(j) : (*v_)(i)) : 0.0;
    return {std::cos(th), std::sin(th), rate, i, j};
  }
  void constant(int row, double c) { phi_(row) += c; }
  void linear(int row, double k, int i) {
    phi_(row) += k * q_(i);
    J_(row, i) += k;
  }
  // + K cos(theta)
  void add_cos(int row, double K, const Angle& a) { add(row, K * a.c, -K * a.s, a); }
  // + K sin(theta)
  void add_sin(int row, double K, const Angle& a) { add(row, K * a.s, K * a.c, a); }

  // Into a MechanicalTerms: phi, the first NH rows of A, phi_t = 0 and,
  // with v, the first NH entries of gamma.
  template <class Terms>
  void store(Terms& terms) const {
    terms.phi = phi_;
    terms.A.template topRows<NH>() = J_;
    terms.phi_t.setZero();
    if (v_) terms.gamma.template head<NH>() = gamma_;
  }

 private:
  void add(int row, double value, double slope, const Angle& a) {
    phi_(row) += value;
    J_(row, a.i) += slope;
    if (a.j >= 0) J_(row, a.j) += slope;
    gamma_(row) -= value * a.rate * a.rate;
  }

  const Eigen::Matrix<double, NQ, 1>& q_;
  const Eigen::Matrix<double, NQ, 1>* v_;
  Eigen::Matrix<double, NH, 1> phi_ = Eigen::Matrix<double, NH, 1>::Zero();
  Eigen::Matrix<double, NH, NQ> J_ = Eigen::Matrix<double, NH, NQ>::Zero();
  Eigen::Matrix<double, NH, 1> gamma_ = Eigen::Matrix<double, NH, 1>::Zero();
};

}  // namespace cstab

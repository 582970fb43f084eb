// A second-order Taylor jet in one variable s: (f(0), f'(0), f''(0)) of a
// function of s, with the arithmetic and the elementary functions the
// models use (the chain rule to second order: g(f)'' = g''(f) f'^2 + g'(f) f'').
//
// Why it exists: the index-1 methods' Jacobians (methods/ode_jacobian.hpp)
// need d/d(q, v) of d^2/ds^2 Phi(t + s, q + s v + s^2 a / 2): three levels
// of derivatives. Three nested Eigen AutoDiffScalars do not compile with the
// models' code (a double no longer converts to the innermost scalar in one
// step), so the two levels in s are this one scalar, under one level of
// AutoDiffScalar (ad::Dual<K, Jet>) for the directions in (q, v).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

namespace cstab::ad {

struct Jet {
  double f0 = 0, f1 = 0, f2 = 0;  // f(0), f'(0), f''(0)

  Jet() = default;
  Jet(double value) : f0(value) {}  // NOLINT: a constant, as AD scalars convert from double
  Jet(double value, double d1, double d2) : f0(value), f1(d1), f2(d2) {}

  double value() const { return f0; }

  Jet& operator+=(const Jet& o) {
    f0 += o.f0, f1 += o.f1, f2 += o.f2;
    return *this;
  }
  Jet& operator-=(const Jet& o) {
    f0 -= o.f0, f1 -= o.f1, f2 -= o.f2;
    return *this;
  }
  Jet& operator*=(const Jet& o) { return *this = *this * o; }
  Jet& operator/=(const Jet& o) { return *this = *this / o; }

  friend Jet operator+(const Jet& a) { return a; }
  friend Jet operator-(const Jet& a) { return {-a.f0, -a.f1, -a.f2}; }
  friend Jet operator+(const Jet& a, const Jet& b) { return {a.f0 + b.f0, a.f1 + b.f1, a.f2 + b.f2}; }
  friend Jet operator-(const Jet& a, const Jet& b) { return {a.f0 - b.f0, a.f1 - b.f1, a.f2 - b.f2}; }
  friend Jet operator*(const Jet& a, const Jet& b) {
    return {a.f0 * b.f0, a.f1 * b.f0 + a.f0 * b.f1, a.f2 * b.f0 + 2 * a.f1 * b.f1 + a.f0 * b.f2};
  }
  friend Jet operator/(const Jet& a, const Jet& b) {
    // a = q b, differentiated twice.
    const double q0 = a.f0 / b.f0;
    const double q1 = (a.f1 - q0 * b.f1) / b.f0;
    return {q0, q1, (a.f2 - 2 * q1 * b.f1 - q0 * b.f2) / b.f0};
  }
  // Comparisons of the values (branches in the models' code).
  friend bool operator<(const Jet& a, const Jet& b) { return a.f0 < b.f0; }
  friend bool operator>(const Jet& a, const Jet& b) { return a.f0 > b.f0; }
  friend bool operator<=(const Jet& a, const Jet& b) { return a.f0 <= b.f0; }
  friend bool operator>=(const Jet& a, const Jet& b) { return a.f0 >= b.f0; }
  friend bool operator==(const Jet& a, const Jet& b) { return a.f0 == b.f0; }
  friend bool operator!=(const Jet& a, const Jet& b) { return a.f0 != b.f0; }
};

// g(a) from g(a0), g'(a0), g''(a0).
inline Jet chain(const Jet& a, double g, double dg, double ddg) {
  return {g, dg * a.f1, ddg * a.f1 * a.f1 + dg * a.f2};
}

inline Jet sin(const Jet& a) {
  const double s = std::sin(a.f0), c = std::cos(a.f0);
  return chain(a, s, c, -s);
}
inline Jet cos(const Jet& a) {
  const double s = std::sin(a.f0), c = std::cos(a.f0);
  return chain(a, c, -s, -c);
}
inline Jet tan(const Jet& a) {
  const double t = std::tan(a.f0), d = 1 + t * t;
  return chain(a, t, d, 2 * t * d);
}
inline Jet exp(const Jet& a) {
  const double e = std::exp(a.f0);
  return chain(a, e, e, e);
}
inline Jet log(const Jet& a) { return chain(a, std::log(a.f0), 1 / a.f0, -1 / (a.f0 * a.f0)); }
inline Jet sqrt(const Jet& a) {
  const double r = std::sqrt(a.f0);
  return chain(a, r, 0.5 / r, -0.25 / (r * a.f0));
}
inline Jet asin(const Jet& a) {
  const double w = 1 - a.f0 * a.f0, d = 1 / std::sqrt(w);
  return chain(a, std::asin(a.f0), d, a.f0 * d / w);
}
inline Jet acos(const Jet& a) {
  const double w = 1 - a.f0 * a.f0, d = 1 / std::sqrt(w);
  return chain(a, std::acos(a.f0), -d, -a.f0 * d / w);
}
inline Jet atan(const Jet& a) {
  const double d = 1 / (1 + a.f0 * a.f0);
  return chain(a, std::atan(a.f0), d, -2 * a.f0 * d * d);
}
inline Jet sinh(const Jet& a) { return chain(a, std::sinh(a.f0), std::cosh(a.f0), std::sinh(a.f0)); }
inline Jet cosh(const Jet& a) { return chain(a, std::cosh(a.f0), std::sinh(a.f0), std::cosh(a.f0)); }
inline Jet tanh(const Jet& a) {
  const double t = std::tanh(a.f0), d = 1 - t * t;
  return chain(a, t, d, -2 * t * d);
}
inline Jet abs(const Jet& a) { return a.f0 < 0 ? -a : a; }
inline Jet abs2(const Jet& a) { return a * a; }
// x^p for a constant p (any sign of x where p is an integer), else exp(p log x).
inline Jet pow(const Jet& x, const Jet& p) {
  if (p.f1 == 0 && p.f2 == 0) {
    const double n = p.f0;
    return chain(x, std::pow(x.f0, n), n * std::pow(x.f0, n - 1), n * (n - 1) * std::pow(x.f0, n - 2));
  }
  return exp(p * log(x));
}
inline Jet atan2(const Jet& y, const Jet& x) {
  // atan(y / x) away from x = 0, without its branch: the derivatives of
  // the angle are (x y' - y x') / r^2 whatever the quadrant.
  const double r2 = x.f0 * x.f0 + y.f0 * y.f0;
  const double d1 = (x.f0 * y.f1 - y.f0 * x.f1) / r2;
  const double num2 = x.f0 * y.f2 - y.f0 * x.f2;  // (x y' - y x')' = x y'' - y x''
  const double r2_1 = 2 * (x.f0 * x.f1 + y.f0 * y.f1);
  return {std::atan2(y.f0, x.f0), d1, (num2 - d1 * r2_1) / r2};
}
inline Jet hypot(const Jet& a, const Jet& b) { return sqrt(a * a + b * b); }
inline bool isfinite(const Jet& a) { return std::isfinite(a.f0) && std::isfinite(a.f1) && std::isfinite(a.f2); }
inline bool isnan(const Jet& a) { return std::isnan(a.f0) || std::isnan(a.f1) || std::isnan(a.f2); }
inline bool isinf(const Jet& a) { return std::isinf(a.f0) || std::isinf(a.f1) || std::isinf(a.f2); }

}  // namespace cstab::ad

namespace Eigen {
// So that Eigen's matrices and AutoDiffScalar<Matrix<Jet, K, 1>> take Jet
// as a real scalar (a double converts to it in one step).
template <>
struct NumTraits<cstab::ad::Jet> : GenericNumTraits<double> {
  using Real = cstab::ad::Jet;
  using NonInteger = cstab::ad::Jet;
  using Nested = cstab::ad::Jet;
  using Literal = double;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 3,
    AddCost = 3,
    MulCost = 9
  };
  static inline Real epsilon() { return Real(std::numeric_limits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(1e-12); }
  static inline Real highest() { return Real(std::numeric_limits<double>::max()); }
  static inline Real lowest() { return Real(std::numeric_limits<double>::lowest()); }
  static inline int digits10() { return std::numeric_limits<double>::digits10; }
};
}  // namespace Eigen

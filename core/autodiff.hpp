// Forward-mode automatic differentiation on Eigen's AutoDiffScalar with
// fixed-size derivative vectors (no heap allocation).
#pragma once

#include <Eigen/Dense>
#include <unsupported/Eigen/AutoDiff>
#include <type_traits>

namespace cstab::ad {

// A scalar carrying K directional derivatives.
template <int K, class Base = double>
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<Base, K, 1>>;

// One more level of a single directional derivative on top of T.
template <class T>
using Nest = Eigen::AutoDiffScalar<Eigen::Matrix<T, 1, 1>>;

// Value of a (possibly nested) scalar at the level of Base.
template <class Base, class T>
Base collapse(const T& x) {
  if constexpr (std::is_same_v<T, Base>) {
    return x;
  } else {
    return collapse<Base>(x.value());
  }
}

// For x = g(Z_L) with Z_{k+1} = Z_k + eps_{k+1} F(Z_k): out[k] = L_F^k g at Z_0.
template <class Base, class T>
void extract_levels(const T& x, Base* out) {
  out[0] = collapse<Base>(x);
  if constexpr (!std::is_same_v<T, Base>) extract_levels<Base>(x.derivatives()(0), out + 1);
}

}  // namespace cstab::ad

namespace cstab::ad {

// The plain double inside any (nested) AD scalar.
template <class T>
double scalar_value(const T& x) {
  if constexpr (std::is_arithmetic_v<T>) {
    return x;
  } else {
    return scalar_value(x.value());
  }
}

// x solving an SPD system M x = b by an unpivoted Cholesky, for any scalar
// type (AD types included); fixed size, no allocation.
template <class S, int N>
Eigen::Matrix<S, N, 1> spd_solve(const Eigen::Matrix<S, N, N>& M, const Eigen::Matrix<S, N, 1>& b) {
  using std::sqrt;
  Eigen::Matrix<S, N, N> L = Eigen::Matrix<S, N, N>::Zero();
  for (int j = 0; j < N; ++j) {
    S d = M(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    L(j, j) = sqrt(d);
    for (int i = j + 1; i < N; ++i) {
      S s = M(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / L(j, j);
    }
  }
  Eigen::Matrix<S, N, 1> y;
  for (int i = 0; i < N; ++i) {
    S s = b(i);
    for (int k = 0; k < i; ++k) s -= L(i, k) * y(k);
    y(i) = s / L(i, i);
  }
  Eigen::Matrix<S, N, 1> x;
  for (int i = N - 1; i >= 0; --i) {
    S s = y(i);
    for (int k = i + 1; k < N; ++k) s -= L(k, i) * x(k);
    x(i) = s / L(i, i);
  }
  return x;
}

}  // namespace cstab::ad

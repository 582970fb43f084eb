// Fixed-size vectors and views of raw state arrays, shared by methods and
// problems.
#pragma once

#include <Eigen/Core>

namespace cstab {

template <class S, int N>
using Vec = Eigen::Matrix<S, N, 1>;

// Fixed-size views of raw state arrays.
template <int N>
Eigen::Map<Vec<double, N>> vmap(double* p) {
  return Eigen::Map<Vec<double, N>>(p);
}
template <int N>
Eigen::Map<const Vec<double, N>> vmap(const double* p) {
  return Eigen::Map<const Vec<double, N>>(p);
}

}  // namespace cstab

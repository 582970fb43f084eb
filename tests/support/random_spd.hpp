// A random symmetric positive definite N x N matrix (B B^T + 0.1 I, B's
// entries uniform in [-1, 1]) for the small-solver tests.
#pragma once

#include <Eigen/Dense>
#include <random>

namespace cstab::testing_support {

template <int N>
Eigen::Matrix<double, N, N> random_spd(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Matrix<double, N, N> B;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) B(i, j) = u(rng);
  return B * B.transpose() + 0.1 * Eigen::Matrix<double, N, N>::Identity();
}

}  // namespace cstab::testing_support

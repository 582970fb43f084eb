// Banded LU with partial pivoting (row interchanges), for the sparse KKT
// systems of long mechanisms: with the unknowns of each body and its joint
// interleaved, [M J^T; J 0] has a narrow band whatever the chain's length.
// An n x n matrix with kl sub- and ku super-diagonals factors in
// O(n kl (kl + ku)) and solves in O(n (2 kl + ku)); the row interchanges
// widen U to kl + ku super-diagonals, which the storage holds from the
// start. Storage is column-major, one column of 2 kl + ku + 1 entries per
// matrix column (entry (i, j) at row kl + ku + i - j), allocated by
// resize(); set_zero(), at(), factor() and solve() do not allocate.
#pragma once

#include <cassert>
#include <cstddef>
#include <vector>

namespace cstab::linalg {

// An n x n matrix with kl sub- and ku super-diagonals, factored in place
// as P A = L U with partial pivoting. Storage (n x (2 kl + ku + 1), the
// kl extra super-diagonals hold the fill of the row interchanges) and the
// pivot vector are allocated by resize(); nothing else allocates.
class BandLu {
 public:
  BandLu() = default;
  BandLu(int n, int kl, int ku) { resize(n, kl, ku); }
  void resize(int n, int kl, int ku);  // n >= 0, kl >= 0, ku >= 0; zeroes the matrix
  int size() const { return n_; }
  int lower() const { return kl_; }  // kl
  int upper() const { return ku_; }  // ku
  void set_zero();                   // every entry of the band (and the fill rows) = 0
  // Entry (i, j), 0-based, inside the band: -kl <= j - i <= ku (checked with assert only).
  double& at(int i, int j) {
    assert(in_band(i, j));
    return ab_[index(i, j)];
  }
  double at(int i, int j) const {  // valid before factor()
    assert(in_band(i, j));
    return ab_[index(i, j)];
  }
  bool in_band(int i, int j) const { return i >= 0 && i < n_ && j >= 0 && j < n_ && j - i <= ku_ && i - j <= kl_; }
  // Factor in place. Returns false if some pivot is exactly zero or not finite
  // (the factorization is then unusable); true otherwise. A NaN among the
  // candidates of a pivot column makes that pivot NaN. The fill rows are
  // cleared first, so a matrix refilled entry by entry after an earlier
  // factor() needs no set_zero().
  bool factor();
  // After a successful factor(): b := A^-1 b, in place (length n). Several
  // right-hand sides may be solved with one factorization.
  void solve(double* b) const;
  // After factor(): min |u_ii| / max |u_ii| (0 if singular) - a cheap
  // singularity indicator, not a condition number. 0 before factor(), 1 for n = 0.
  double pivot_ratio() const;

 private:
  enum class State { kAssembled, kFactored, kSingular };

  // Storage offset of (i, j), i - j in [-(kl + ku), kl].
  std::size_t index(int i, int j) const { return std::size_t(kl_ + ku_ + i - j) + std::size_t(j) * std::size_t(ld_); }

  int n_ = 0;
  int kl_ = 0;
  int ku_ = 0;
  int ld_ = 1;  // 2 kl + ku + 1
  State state_ = State::kAssembled;
  std::vector<double> ab_;
  std::vector<int> pivots_;  // row interchanged with row j at step j
};

}  // namespace cstab::linalg

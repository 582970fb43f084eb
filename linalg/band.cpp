#include "linalg/band.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace cstab::linalg {

void BandLu::resize(int n, int kl, int ku) {
  assert(n >= 0 && kl >= 0 && ku >= 0);
  n_ = n;
  kl_ = kl;
  ku_ = ku;
  ld_ = 2 * kl + ku + 1;
  ab_.assign(std::size_t(n) * std::size_t(ld_), 0.0);
  pivots_.assign(std::size_t(n), 0);
  state_ = State::kAssembled;
}

void BandLu::set_zero() {
  std::fill(ab_.begin(), ab_.end(), 0.0);
  state_ = State::kAssembled;
}

// Column j of the storage holds rows j - kv .. j + kl of column j of the
// matrix (kv = kl + ku, the band of U), the diagonal at offset kv. Step j
// picks the largest |a(i, j)| for i in j .. j + kl, swaps that row with row
// j over the columns it may reach, stores the multipliers l(i, j) in place
// of a(i, j) and updates the trailing block. The multipliers of step j are
// not swapped by the later steps: solve() applies the interchanges and the
// eliminations in the same order.
bool BandLu::factor() {
  const int n = n_, kl = kl_, kv = kl_ + ku_;
  const std::ptrdiff_t ld = ld_;
  double* const ab = ab_.data();
  // The fill rows (offsets 0 .. kl - 1: super-diagonals ku + 1 .. kv) start at zero.
  for (int j = 0; j < n; ++j) std::fill(ab + j * ld, ab + j * ld + kl, 0.0);
  state_ = State::kSingular;
  // ju: the last column any row of the active window can reach (row j
  // reaches j + ku until an interchange brings in a row reaching further).
  int ju = -1;
  for (int j = 0; j < n; ++j) {
    double* const col = ab + j * ld + kv;  // col[r] = a(j + r, j), r in -kv .. kl
    const int km = std::min(kl, n - 1 - j);
    int p = 0;
    double amax = -1.0;
    for (int r = 0; r <= km; ++r) {
      const double v = std::fabs(col[r]);
      if (std::isnan(v)) return false;  // a NaN candidate: the pivot is NaN
      if (v > amax) {
        amax = v;
        p = r;
      }
    }
    if (amax == 0.0 || std::isinf(amax)) return false;
    pivots_[std::size_t(j)] = j + p;
    ju = std::max(ju, std::min(j + p + ku_, n - 1));
    // Interchange rows j and j + p over columns j .. ju: in column c, row i
    // sits at offset kv + i - c, so one stride of ld - 1 per column.
    if (p != 0) {
      double* a = col;
      for (int c = j; c <= ju; ++c, a += ld - 1) std::swap(a[0], a[p]);
    }
    const double pivot = col[0];
    for (int r = 1; r <= km; ++r) col[r] /= pivot;
    if (km > 0) {
      // a(j + r, c) -= l(j + r, j) a(j, c), for c in j + 1 .. ju.
      double* a = col + ld - 1;  // a[0] = a(j, j + 1)
      for (int c = j + 1; c <= ju; ++c, a += ld - 1) {
        const double t = a[0];
        if (t == 0.0) continue;
        for (int r = 1; r <= km; ++r) a[r] -= col[r] * t;
      }
    }
  }
  state_ = State::kFactored;
  return true;
}

void BandLu::solve(double* b) const {
  assert(state_ == State::kFactored);
  const int n = n_, kl = kl_, kv = kl_ + ku_;
  const std::ptrdiff_t ld = ld_;
  const double* const ab = ab_.data();
  // b := L^-1 P b, interchanges and eliminations interleaved as in factor().
  if (kl > 0) {
    for (int j = 0; j < n - 1; ++j) {
      const int p = pivots_[std::size_t(j)];
      if (p != j) std::swap(b[j], b[p]);
      const double t = b[j];
      if (t == 0.0) continue;
      const double* const col = ab + j * ld + kv;
      const int km = std::min(kl, n - 1 - j);
      for (int r = 1; r <= km; ++r) b[j + r] -= col[r] * t;
    }
  }
  // b := U^-1 b by columns, U having kv super-diagonals.
  for (int j = n - 1; j >= 0; --j) {
    const double* const col = ab + j * ld + kv;  // col[r] = u(j + r, j), r in -kv .. 0
    b[j] /= col[0];
    const double t = b[j];
    if (t == 0.0) continue;
    const int top = std::min(kv, j);
    for (int r = 1; r <= top; ++r) b[j - r] -= col[-r] * t;
  }
}

double BandLu::pivot_ratio() const {
  if (state_ != State::kFactored) return 0.0;
  if (n_ == 0) return 1.0;
  const int kv = kl_ + ku_;
  double lo = std::fabs(ab_[std::size_t(kv)]), hi = lo;
  for (int j = 1; j < n_; ++j) {
    const double u = std::fabs(ab_[std::size_t(kv) + std::size_t(j) * std::size_t(ld_)]);
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  return lo / hi;
}

}  // namespace cstab::linalg

// linalg::BandLu, the banded partial-pivoting LU for the KKT systems of long
// mechanisms, against Eigen's dense PartialPivLU of the same matrices:
// random band matrices (diagonally dominant, and with a small diagonal so
// that rows are interchanged and U fills its kl extra super-diagonals), the
// interleaved KKT matrix of an anchored chain of bars, singular matrices,
// the pivot ratio, several right-hand sides, reuse after resize() and
// refill, and no operator new in factor() or solve().
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <string>
#include <vector>

#include "linalg/band.hpp"
#include "tests/support/escape.hpp"

// Every operator new of this binary is counted (std::vector allocates
// through it; band.cpp uses nothing else). None of them is inlined, so that
// GCC does not see malloc() meet operator delete (-Wmismatched-new-delete).
namespace {
std::atomic<long> g_operator_news{0};
}  // namespace

__attribute__((noinline)) void* operator new(std::size_t size) {
  g_operator_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void operator delete(void* p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace cstab {
namespace {

using linalg::BandLu;

// Entries uniform in [-1, 1] inside the band, zero outside; the diagonal is
// `diagonal_shift` + `diagonal_scale` * uniform (shift kl + ku + 1 and scale
// 1: diagonally dominant; shift 0 and scale 1e-3: rows are interchanged, but
// the matrix is as ill-conditioned as chance makes it: the sweep's n = 200
// ones reach 1e9 for kl = ku = 1 and 6e15 for kl = 3, ku = 1).
Eigen::MatrixXd random_band(int n, int kl, int ku, double diagonal_shift, double diagonal_scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - ku); i <= std::min(n - 1, j + kl); ++i)
      a(i, j) = i == j ? diagonal_shift + diagonal_scale * u(rng) : u(rng);
  return a;
}

// random_band with the small diagonal (1e-3), plus one entry of magnitude
// kl + ku + 2 per column on a row permutation that stays inside the band:
// cycles of L <= kl + 1 columns j .. j + L - 1, column j's entry in row
// j + L - 1 and column j + i's in row j + i - 1 (L = 1 where ku = 0). The
// rows so permuted are strictly diagonally dominant, so the matrix is well
// conditioned, yet its diagonal is small wherever a cycle moves rows:
// partial pivoting must interchange them and U fills up to kl + ku.
Eigen::MatrixXd pivoting_band(int n, int kl, int ku, unsigned seed) {
  Eigen::MatrixXd a = random_band(n, kl, ku, 0.0, 1e-3, seed);
  std::mt19937 rng(seed + 1);
  const double big = kl + ku + 2;
  for (int j = 0; j < n;) {
    const int length = std::uniform_int_distribution<int>(1, std::min(ku >= 1 ? kl + 1 : 1, n - j))(rng);
    for (int i = 0; i < length; ++i) a(i == 0 ? j + length - 1 : j + i - 1, j + i) += rng() % 2 ? big : -big;
    j += length;
  }
  return a;
}

Eigen::VectorXd random_vector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b(i) = u(rng);
  return b;
}

// Copies the band of `a` into `lu` (every in-band entry, zeros included);
// the test fails if `a` has a nonzero outside the band.
void fill(BandLu& lu, const Eigen::MatrixXd& a) {
  ASSERT_EQ(lu.size(), a.rows());
  for (int j = 0; j < lu.size(); ++j)
    for (int i = 0; i < lu.size(); ++i) {
      if (lu.in_band(i, j))
        lu.at(i, j) = a(i, j);
      else
        ASSERT_EQ(a(i, j), 0.0) << "entry (" << i << ", " << j << ") outside the band";
    }
}

Eigen::VectorXd band_solve(const BandLu& lu, const Eigen::VectorXd& b) {
  Eigen::VectorXd x = b;
  lu.solve(x.data());
  return x;
}

double relative_error(const Eigen::VectorXd& x, const Eigen::VectorXd& reference) {
  return (x - reference).norm() / reference.norm();
}

// min |u_ii| / max |u_ii| of Eigen's dense LU (same pivot rule, same pivots).
double dense_pivot_ratio(const Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
  const Eigen::VectorXd d = lu.matrixLU().diagonal().cwiseAbs();
  return d.minCoeff() / d.maxCoeff();
}

// Gaussian elimination without row interchanges (dense), to show what the
// interchanges buy.
Eigen::VectorXd solve_without_pivoting(Eigen::MatrixXd a, Eigen::VectorXd b) {
  const Eigen::Index n = a.rows();
  for (Eigen::Index k = 0; k < n; ++k)
    for (Eigen::Index i = k + 1; i < n; ++i) {
      const double l = a(i, k) / a(k, k);
      a.row(i).tail(n - k) -= l * a.row(k).tail(n - k);
      b(i) -= l * b(k);
    }
  for (Eigen::Index k = n - 1; k >= 0; --k) b(k) = (b(k) - a.row(k).tail(n - 1 - k).dot(b.tail(n - 1 - k))) / a(k, k);
  return b;
}

TEST(BandLu, AccessorsAndBandShape) {
  BandLu lu(6, 2, 1);
  EXPECT_EQ(lu.size(), 6);
  EXPECT_EQ(lu.lower(), 2);
  EXPECT_EQ(lu.upper(), 1);
  EXPECT_TRUE(lu.in_band(0, 0));
  EXPECT_TRUE(lu.in_band(0, 1));
  EXPECT_FALSE(lu.in_band(0, 2));  // second super-diagonal: ku = 1
  EXPECT_TRUE(lu.in_band(2, 0));
  EXPECT_FALSE(lu.in_band(3, 0));  // third sub-diagonal: kl = 2
  EXPECT_TRUE(lu.in_band(5, 5));
  EXPECT_FALSE(lu.in_band(6, 6));
  EXPECT_FALSE(lu.in_band(-1, 0));
  EXPECT_FALSE(lu.in_band(4, 6));
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (lu.in_band(i, j)) {
        EXPECT_EQ(lu.at(i, j), 0.0) << i << ", " << j;
      }
  // Distinct entries do not share storage.
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (lu.in_band(i, j)) lu.at(i, j) = 10 * i + j;
  const BandLu& c = lu;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (lu.in_band(i, j)) {
        EXPECT_EQ(c.at(i, j), 10.0 * i + j) << i << ", " << j;
      }
  lu.set_zero();
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (lu.in_band(i, j)) {
        EXPECT_EQ(c.at(i, j), 0.0) << i << ", " << j;
      }
}

// Three kinds per size and band: diagonally dominant (no interchanges),
// pivoting_band (interchanges, well conditioned): the solution within 1e-10
// of the dense one and the same pivots (the same diagonal of U); and the
// plain small-diagonal random_band, whose conditioning is left to chance:
// a backward-stable solve, residual within 1e-12 of |A| |x|.
TEST(BandLu, MatchesDensePartialPivLuOnRandomBands) {
  const int sizes[] = {1, 2, 5, 17, 200};
  const int bands[][2] = {{0, 0}, {1, 1}, {2, 3}, {3, 1}, {5, 5}};
  int cases = 0, interchanged = 0;
  double worst = 0;
  for (int n : sizes)
    for (const auto& band : bands)
      for (int kind = 0; kind < 3; ++kind) {
        const int kl = band[0], ku = band[1];
        const unsigned seed = unsigned(1000 * n + 100 * kl + 10 * ku + kind);
        const Eigen::MatrixXd a = kind == 0   ? random_band(n, kl, ku, kl + ku + 1, 1.0, seed)
                                  : kind == 1 ? pivoting_band(n, kl, ku, seed)
                                              : random_band(n, kl, ku, 0.0, 1e-3, seed);
        const Eigen::VectorXd b = random_vector(n, seed + 7);
        const std::string where = "n " + std::to_string(n) + " kl " + std::to_string(kl) + " ku " + std::to_string(ku) +
                                  " kind " + std::to_string(kind);
        BandLu lu(n, kl, ku);
        fill(lu, a);
        ASSERT_TRUE(lu.factor()) << where;
        const Eigen::VectorXd x = band_solve(lu, b);
        EXPECT_LE((a * x - b).norm(), 1e-12 * (a.norm() * x.norm())) << where;
        ++cases;
        if (kind == 2) continue;
        const Eigen::PartialPivLU<Eigen::MatrixXd> dense(a);
        const double error = relative_error(x, dense.solve(b));
        EXPECT_LE(error, 1e-10) << where;
        EXPECT_NEAR(lu.pivot_ratio(), dense_pivot_ratio(dense), 1e-10 * dense_pivot_ratio(dense)) << where;
        worst = std::max(worst, error);
        const Eigen::VectorXi rows = dense.permutationP().indices();
        const bool identity = (rows.array() == Eigen::VectorXi::LinSpaced(n, 0, n - 1).array()).all();
        if (kind == 0 || kl == 0) {
          EXPECT_TRUE(identity) << where;
        }
        if (kind == 1 && kl > 0 && n >= 5) {
          EXPECT_FALSE(identity) << where;
        }
        if (!identity) {
          ++interchanged;
        }
      }
  EXPECT_EQ(cases, 75);
  EXPECT_GE(interchanged, 12);  // at least pivoting_band's with kl > 0 and n >= 5
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_relative_error", text);
  RecordProperty("cases_with_interchanges", interchanged);
}

TEST(BandLu, SmallPivotIsInterchanged) {
  // [1e-20 1; 1 1] x = [1; 2]: x ~ [1; 1]. Without interchanges the
  // multiplier 1e20 wipes out the second row and x_0 comes out 0.
  Eigen::MatrixXd a(2, 2);
  a << 1e-20, 1, 1, 1;
  const Eigen::Vector2d b(1, 2);
  const Eigen::VectorXd naive = solve_without_pivoting(a, b);
  EXPECT_GT(std::abs(naive(0) - 1.0), 0.5);
  BandLu lu(2, 1, 1);
  fill(lu, a);
  ASSERT_TRUE(lu.factor());
  const Eigen::VectorXd x = band_solve(lu, b);
  EXPECT_NEAR(x(0), 1.0, 1e-15);
  EXPECT_NEAR(x(1), 1.0, 1e-15);
}

TEST(BandLu, ZeroLeadingEntryNeedsInterchanges) {
  // Tridiagonal with a(0, 0) = 0: elimination without interchanges divides
  // by zero; the banded LU swaps rows 0 and 1.
  const int n = 9;
  Eigen::MatrixXd a = random_band(n, 1, 1, 3.0, 1.0, 42);
  a(0, 0) = 0.0;
  const Eigen::VectorXd b = random_vector(n, 43);
  EXPECT_FALSE(solve_without_pivoting(a, b).allFinite());
  BandLu lu(n, 1, 1);
  fill(lu, a);
  ASSERT_TRUE(lu.factor());
  const Eigen::VectorXd x = band_solve(lu, b);
  EXPECT_LE(relative_error(x, a.partialPivLu().solve(b)), 1e-12);
}

TEST(BandLu, InterchangesFillTheExtraSuperDiagonals) {
  // kl = 2, ku = 1, the second sub-diagonal dominant: every step takes row
  // j + 2 as its pivot row, whose entries reach column j + 3 = j + kl + ku.
  const int n = 12, kl = 2, ku = 1;
  Eigen::MatrixXd a = random_band(n, kl, ku, 0.0, 1e-2, 5);
  for (int j = 0; j + 2 < n; ++j) a(j + 2, j) = (j % 2 ? -10.0 : 10.0) + 0.1 * j;
  const Eigen::VectorXd b = random_vector(n, 6);
  BandLu lu(n, kl, ku);
  fill(lu, a);
  ASSERT_TRUE(lu.factor());
  const Eigen::PartialPivLU<Eigen::MatrixXd> dense(a);
  // The dense LU moves row 2 up first: the same interchange.
  EXPECT_EQ(dense.permutationP().indices()(2), 0);
  EXPECT_LE(relative_error(band_solve(lu, b), dense.solve(b)), 1e-12);
  EXPECT_NEAR(lu.pivot_ratio(), dense_pivot_ratio(dense), 1e-12);
}

// KKT matrix [M J^T; J 0] of a planar chain of `bodies` bars of length 1,
// bar 0 pinned to the ground at its base, bar k's base pinned to bar k-1's
// tip. Unknowns per bar k: the joint's two multipliers, then x, y, theta;
// a joint couples its bar and the previous one only, so kl = ku = 4.
Eigen::MatrixXd chain_kkt(int bodies, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 5 * bodies;
  const double half = 0.5;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  std::vector<double> theta(std::size_t(bodies), 0.0);
  for (int k = 0; k < bodies; ++k) {
    theta[std::size_t(k)] = 3.0 * u(rng);
    const double m = 1.25 + 0.75 * u(rng);
    const int q = 5 * k + 2;
    a(q, q) = m;
    a(q + 1, q + 1) = m;
    a(q + 2, q + 2) = m / 12.0;
  }
  auto couple = [&a](int row, int col, double value) {
    a(row, col) = value;
    a(col, row) = value;
  };
  for (int k = 0; k < bodies; ++k) {
    const double s = std::sin(theta[std::size_t(k)]), c = std::cos(theta[std::size_t(k)]);
    const int lambda = 5 * k, q = 5 * k + 2;
    // Base of bar k: (x, y) - half (cos, sin).
    couple(lambda, q, 1.0);
    couple(lambda + 1, q + 1, 1.0);
    couple(lambda, q + 2, half * s);
    couple(lambda + 1, q + 2, -half * c);
    if (k == 0) continue;
    // Minus the tip of bar k - 1: (x, y) + half (cos, sin).
    const double sp = std::sin(theta[std::size_t(k - 1)]), cp = std::cos(theta[std::size_t(k - 1)]);
    const int qp = 5 * (k - 1) + 2;
    couple(lambda, qp, -1.0);
    couple(lambda + 1, qp + 1, -1.0);
    couple(lambda, qp + 2, half * sp);
    couple(lambda + 1, qp + 2, -half * cp);
  }
  return a;
}

TEST(BandLu, ChainKktSaddlePoint) {
  const int bodies = 60, n = 5 * bodies;
  const Eigen::MatrixXd a = chain_kkt(bodies, 11);
  ASSERT_TRUE(a.isApprox(a.transpose(), 0.0));
  EXPECT_EQ(a(0, 0), 0.0);  // a multiplier first: the factorization must interchange rows
  BandLu lu(n, 4, 4);
  fill(lu, a);  // fails on any entry outside kl = ku = 4
  ASSERT_TRUE(lu.factor());
  for (unsigned seed = 0; seed < 3; ++seed) {
    const Eigen::VectorXd b = random_vector(n, 100 + seed);
    const Eigen::VectorXd x = band_solve(lu, b);
    EXPECT_LE((a * x - b).norm() / b.norm(), 1e-12) << "seed " << seed;
    EXPECT_LE(relative_error(x, a.partialPivLu().solve(b)), 1e-10) << "seed " << seed;
  }
  // Indefinite: the multipliers' block has negative pivots in LDL^T, so the
  // matrix has eigenvalues of both signs.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a, Eigen::EigenvaluesOnly);
  EXPECT_LT(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_GT(eig.eigenvalues().maxCoeff(), 0.0);
}

TEST(BandLu, SingularMatricesAreReported) {
  const int n = 10, kl = 2, ku = 3;
  {
    Eigen::MatrixXd a = random_band(n, kl, ku, 6.0, 1.0, 21);
    a.row(4).setZero();
    BandLu lu(n, kl, ku);
    fill(lu, a);
    EXPECT_FALSE(lu.factor());
    EXPECT_EQ(lu.pivot_ratio(), 0.0);
  }
  {
    // A zero column inside the band: no candidate pivot at that step.
    Eigen::MatrixXd a = random_band(n, kl, ku, 0.0, 1e-3, 22);
    a.col(6).setZero();
    BandLu lu(n, kl, ku);
    fill(lu, a);
    EXPECT_FALSE(lu.factor());
    EXPECT_EQ(lu.pivot_ratio(), 0.0);
  }
  {
    // Nonzero everywhere in the band, yet the second pivot is exactly 0.
    BandLu lu(2, 1, 1);
    lu.at(0, 0) = 2;
    lu.at(0, 1) = 4;
    lu.at(1, 0) = 1;
    lu.at(1, 1) = 2;
    EXPECT_FALSE(lu.factor());
  }
  {
    // Not finite: a NaN below the diagonal (never the largest by
    // comparison) or an infinite entry.
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      Eigen::MatrixXd a = random_band(n, kl, ku, 6.0, 1.0, 23);
      BandLu lu(n, kl, ku);
      fill(lu, a);
      lu.at(5, 3) = bad;
      EXPECT_FALSE(lu.factor()) << bad;
    }
    // A NaN multiplier that no update would spread (the pivot row is zero
    // to the right of the pivot): only the pivot search sees it.
    BandLu lu(2, 1, 1);
    lu.at(0, 0) = 2;
    lu.at(1, 0) = std::numeric_limits<double>::quiet_NaN();
    lu.at(1, 1) = 1;
    EXPECT_FALSE(lu.factor());
  }
}

TEST(BandLu, PivotRatio) {
  BandLu identity(7, 1, 2);
  for (int i = 0; i < 7; ++i) identity.at(i, i) = 1.0;
  EXPECT_EQ(identity.pivot_ratio(), 0.0);  // not factored yet
  ASSERT_TRUE(identity.factor());
  EXPECT_EQ(identity.pivot_ratio(), 1.0);

  BandLu diagonal(3, 0, 0);
  diagonal.at(0, 0) = 2;
  diagonal.at(1, 1) = -4;
  diagonal.at(2, 2) = 8;
  ASSERT_TRUE(diagonal.factor());
  EXPECT_EQ(diagonal.pivot_ratio(), 0.25);

  // The Neumann Laplacian tridiag(-1, 2, -1) with 1 in both corners is
  // singular (constants are its kernel); with 1e-13 added to the last
  // corner the last pivot is ~1e-13, the others 1.
  const int n = 50;
  BandLu nearly(n, 1, 1);
  for (int i = 0; i < n; ++i) {
    nearly.at(i, i) = (i == 0 || i == n - 1) ? 1.0 : 2.0;
    if (i > 0) nearly.at(i, i - 1) = -1.0;
    if (i + 1 < n) nearly.at(i, i + 1) = -1.0;
  }
  nearly.at(n - 1, n - 1) += 1e-13;
  ASSERT_TRUE(nearly.factor());
  EXPECT_LT(nearly.pivot_ratio(), 1e-12);
  EXPECT_GT(nearly.pivot_ratio(), 1e-14);
}

TEST(BandLu, SeveralRightHandSidesOneFactorization) {
  const int n = 60, kl = 3, ku = 2;
  const Eigen::MatrixXd a = pivoting_band(n, kl, ku, 31);
  BandLu lu(n, kl, ku);
  fill(lu, a);
  ASSERT_TRUE(lu.factor());
  const Eigen::PartialPivLU<Eigen::MatrixXd> dense(a);
  std::vector<Eigen::VectorXd> first;
  for (unsigned seed = 0; seed < 5; ++seed) {
    const Eigen::VectorXd b = random_vector(n, 200 + seed);
    first.push_back(band_solve(lu, b));
    EXPECT_LE(relative_error(first.back(), dense.solve(b)), 1e-10) << "seed " << seed;
  }
  // solve() leaves the factorization as it was: the same answers again.
  for (unsigned seed = 0; seed < 5; ++seed)
    EXPECT_EQ(band_solve(lu, random_vector(n, 200 + seed)), first[seed]) << "seed " << seed;
}

TEST(BandLu, ResizeSmallerAndLargerThenReuse) {
  BandLu lu(30, 2, 3);
  struct Shape {
    int n, kl, ku;
  };
  const Shape shapes[] = {{30, 2, 3}, {7, 1, 1}, {120, 5, 4}, {3, 5, 5}};
  unsigned seed = 50;
  for (const Shape& s : shapes) {
    lu.resize(s.n, s.kl, s.ku);
    EXPECT_EQ(lu.size(), s.n);
    EXPECT_EQ(lu.lower(), s.kl);
    EXPECT_EQ(lu.upper(), s.ku);
    for (int i = 0; i < s.n; ++i)
      for (int j = 0; j < s.n; ++j)
        if (lu.in_band(i, j)) {
          ASSERT_EQ(lu.at(i, j), 0.0) << "resize leaves (" << i << ", " << j << ")";
        }
    const Eigen::MatrixXd a = pivoting_band(s.n, s.kl, s.ku, ++seed);
    const Eigen::VectorXd b = random_vector(s.n, ++seed);
    fill(lu, a);
    ASSERT_TRUE(lu.factor()) << "n " << s.n;
    EXPECT_LE(relative_error(band_solve(lu, b), a.partialPivLu().solve(b)), 1e-10) << "n " << s.n;
  }
  lu.resize(0, 0, 0);
  EXPECT_EQ(lu.size(), 0);
  EXPECT_TRUE(lu.factor());
  EXPECT_EQ(lu.pivot_ratio(), 1.0);
  lu.solve(nullptr);  // nothing to do
}

TEST(BandLu, RefillAfterFactorWithoutSetZero) {
  // factor() leaves L, U and fill in the storage; refilling every band
  // entry (or set_zero() and the nonzeros only) gives a fresh matrix.
  const int n = 40, kl = 3, ku = 2;
  BandLu lu(n, kl, ku);
  fill(lu, pivoting_band(n, kl, ku, 61));
  ASSERT_TRUE(lu.factor());
  const Eigen::MatrixXd a = pivoting_band(n, kl, ku, 62);
  const Eigen::VectorXd b = random_vector(n, 63);
  fill(lu, a);
  ASSERT_TRUE(lu.factor());
  EXPECT_LE(relative_error(band_solve(lu, b), a.partialPivLu().solve(b)), 1e-10);

  const Eigen::MatrixXd t = pivoting_band(n, 1, 1, 64);  // tridiagonal inside the wider band
  lu.set_zero();
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - 1); i <= std::min(n - 1, j + 1); ++i) lu.at(i, j) = t(i, j);
  ASSERT_TRUE(lu.factor());
  EXPECT_LE(relative_error(band_solve(lu, b), t.partialPivLu().solve(b)), 1e-10);
}

TEST(BandLu, FactorAndSolveDoNotAllocate) {
  const int n = 200, kl = 5, ku = 5;
  const Eigen::MatrixXd a = pivoting_band(n, kl, ku, 71);
  Eigen::VectorXd b = random_vector(n, 72);
  BandLu lu(n, kl, ku);
  fill(lu, a);
  // The counter sees allocations, or the zero below would prove nothing.
  const long before_vector = g_operator_news.load();
  {
    std::vector<double> probe(10, 1.0);
    testing::escape(probe.data());
  }
  ASSERT_GT(g_operator_news.load(), before_vector);

  const long before = g_operator_news.load();
  const bool ok = lu.factor();
  lu.solve(b.data());
  lu.set_zero();
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - ku); i <= std::min(n - 1, j + kl); ++i) lu.at(i, j) = a(i, j);
  const bool again = lu.factor();
  const double ratio = lu.pivot_ratio();
  const long allocations = g_operator_news.load() - before;
  EXPECT_TRUE(ok);
  EXPECT_TRUE(again);
  EXPECT_GT(ratio, 0.0);
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace cstab

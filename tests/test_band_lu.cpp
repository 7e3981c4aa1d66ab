// Banded LU with partial pivoting (core/band_matrix.hpp) against Eigen's dense
// PartialPivLU, its backward error, singular matrices, and that factorize + solve on a
// resized object allocate nothing.
//
// Eigen allocates with malloc, not operator new, so the allocation test uses both the
// counting operator new below (for std::vector and anything else of the standard library)
// and Eigen's own runtime check, which needs this macro before Eigen is included. This
// file is its own executable, so the macro does not make Eigen's inline code differ
// between translation units of one program.
#define EIGEN_RUNTIME_NO_MALLOC

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <string>

#include "core/band_matrix.hpp"

// Counting replacements of the global allocation functions. The array and nothrow forms
// of the standard library forward to these; the aligned forms are not used here. Not
// inlined: inlined, g++ sees a `new` expression's pointer reach free() and warns
// (-Wmismatched-new-delete) although both sides are these replacements.
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

[[gnu::noinline]] void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new[](std::size_t size) { return ::operator new(size); }
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace stepbench;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

enum class kind {
  dominant,       // diagonally dominant by rows and columns: partial pivoting swaps nothing
  swapped_pairs,  // a zero diagonal entry in every other row; needs kl, ku >= 1
  random,         // entries as drawn: pivots wherever they fall, conditioning left to the seed
};

double off_diagonal_sum(const band_matrix& a, Index i, Index skip) {  // row i, leaving out columns i and skip
  double s = 0.0;
  for (Index j = std::max<Index>(0, i - a.kl()); j <= std::min(a.rows() - 1, i + a.ku()); ++j)
    if (j != i && j != skip) s += std::abs(a(i, j));
  return s;
}

double signed_like(double x, double magnitude) { return x < 0.0 ? -magnitude : magnitude; }

// Entries uniform in [-1, 1] on the band (fixed seed per case), then shaped by `k`.
//
// swapped_pairs: for each even i < n - 1, A(i, i) = 0 and A(i + 1, i), A(i, i + 1) exceed
// the rest of their rows, so swapping rows i and i + 1 makes A diagonally dominant by rows
// with margin 1: well conditioned at every n (||(PA)^-1||_inf <= 1), yet the elimination
// must swap at every even step.
band_matrix random_band(Index n, Index kl, Index ku, kind k, unsigned seed) {
  band_matrix a(n, kl, ku);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index j = 0; j < n; ++j)
    for (Index i = std::max<Index>(0, j - ku); i <= std::min(n - 1, j + kl); ++i) a(i, j) = u(rng);
  if (k == kind::random) return a;
  if (k == kind::swapped_pairs) {
    assert(kl >= 1 && ku >= 1);
    for (Index i = 0; i + 1 < n; i += 2) {
      a(i, i) = 0.0;
      a(i, i + 1) = signed_like(a(i, i + 1), 1.0 + off_diagonal_sum(a, i, i + 1));
      a(i + 1, i) = signed_like(a(i + 1, i), 1.0 + off_diagonal_sum(a, i + 1, i) + std::abs(a(i + 1, i + 1)));
    }
    if (n % 2 == 1) a(n - 1, n - 1) = signed_like(a(n - 1, n - 1), 1.0 + off_diagonal_sum(a, n - 1, n - 1));
    return a;
  }
  for (Index i = 0; i < n; ++i) {
    double off = 1.0 + off_diagonal_sum(a, i, i);  // 1 + the row's and the column's off-diagonal magnitudes
    for (Index r = std::max<Index>(0, i - ku); r <= std::min(n - 1, i + kl); ++r)
      if (r != i) off += std::abs(a(r, i));
    a(i, i) = signed_like(a(i, i), off);
  }
  return a;
}

MatrixXd to_dense(const band_matrix& a) {
  MatrixXd d = MatrixXd::Zero(a.rows(), a.cols());
  for (Index j = 0; j < a.cols(); ++j)
    for (Index i = 0; i < a.rows(); ++i)
      if (a.in_band(i, j)) d(i, j) = a(i, j);
  return d;
}

VectorXd random_vector(Index n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VectorXd v(n);
  for (Index i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// ||A||_inf, the largest row sum of magnitudes.
double norm_inf(const band_matrix& a) {
  VectorXd row_sums = VectorXd::Zero(a.rows());
  for (Index j = 0; j < a.cols(); ++j)
    for (Index i = std::max<Index>(0, j - a.ku()); i <= std::min(a.rows() - 1, j + a.kl()); ++i)
      row_sums[i] += std::abs(a(i, j));
  return a.rows() == 0 ? 0.0 : row_sums.maxCoeff();
}

// A x, on the band only.
VectorXd times(const band_matrix& a, const VectorXd& x) {
  VectorXd y = VectorXd::Zero(a.rows());
  for (Index j = 0; j < a.cols(); ++j)
    for (Index i = std::max<Index>(0, j - a.ku()); i <= std::min(a.rows() - 1, j + a.kl()); ++i) y[i] += a(i, j) * x[j];
  return y;
}

// Normwise backward error ||A x - b|| / (||A|| ||x||), infinity norms.
double backward_error(const band_matrix& a, const VectorXd& x, const VectorXd& b) {
  const VectorXd r = times(a, x) - b;
  return r.lpNorm<Eigen::Infinity>() / (norm_inf(a) * x.lpNorm<Eigen::Infinity>());
}

long interchanges(const band_lu& lu) {
  long swaps = 0;
  for (std::size_t j = 0; j < lu.pivots().size(); ++j) swaps += lu.pivots()[j] != static_cast<Index>(j);
  return swaps;
}

struct band_case {
  Index n, kl, ku;
  kind k;
  unsigned seed = 1;
};

std::string case_name(const testing::TestParamInfo<band_case>& info) {
  const band_case& c = info.param;
  const char* k = c.k == kind::dominant ? "dominant" : c.k == kind::swapped_pairs ? "swapped_pairs" : "random";
  return "n" + std::to_string(c.n) + "_kl" + std::to_string(c.kl) + "_ku" + std::to_string(c.ku) + "_" + k;
}

class band_lu_vs_dense : public testing::TestWithParam<band_case> {};

}  // namespace

TEST_P(band_lu_vs_dense, solves_as_partial_piv_lu_does) {
  const band_case c = GetParam();
  const unsigned seed = static_cast<unsigned>(1000 * c.n + 100 * c.kl + 10 * c.ku) + c.seed;
  const band_matrix a = random_band(c.n, c.kl, c.ku, c.k, seed);
  const MatrixXd d = to_dense(a);
  const Eigen::PartialPivLU<MatrixXd> dense(d);

  // Two backward-stable solvers agree to about cond(A) eps, so the 1e-12 below tests the
  // band code only on a well-conditioned matrix: check that first (1-norm, exact inverse).
  const double cond = d.cwiseAbs().colwise().sum().maxCoeff() * dense.inverse().cwiseAbs().colwise().sum().maxCoeff();
  ASSERT_LT(cond, 1e3) << "test matrix too ill-conditioned for a 1e-12 comparison; pick another seed";

  band_lu lu(c.n, c.kl, c.ku);
  ASSERT_TRUE(lu.factorize(a));
  EXPECT_EQ(lu.zero_pivot(), -1);
  if (c.k == kind::dominant) {
    EXPECT_EQ(interchanges(lu), 0) << "column diagonal dominance needs no interchanges";
  } else if (c.k == kind::swapped_pairs) {
    EXPECT_GE(interchanges(lu), c.n / 2) << "every zero A(i, i), i even, must be pivoted away";
  } else if (c.n >= 3) {
    EXPECT_GT(interchanges(lu), 0);
  }

  for (unsigned rhs = 0; rhs < 3; ++rhs) {
    const VectorXd b = random_vector(c.n, seed + 7919 * (rhs + 1));
    VectorXd x = b;
    lu.solve_in_place(x);
    const VectorXd x_dense = dense.solve(b);
    EXPECT_LE((x - x_dense).lpNorm<Eigen::Infinity>() / x_dense.lpNorm<Eigen::Infinity>(), 1e-12) << "rhs " << rhs;
    EXPECT_LT(backward_error(a, x, b), 1e-14) << "rhs " << rhs;
  }
}

// n < kl + ku + 1 makes the band the whole matrix; n = 1 and kl = 0 or ku = 0 are the
// degenerate ends. The random cases' seeds are picked for cond_1(A) < 1e3.
INSTANTIATE_TEST_SUITE_P(
    shapes, band_lu_vs_dense,
    testing::Values(
        band_case{1, 0, 0, kind::dominant}, band_case{1, 2, 3, kind::dominant}, band_case{2, 1, 1, kind::dominant},
        band_case{4, 3, 2, kind::dominant}, band_case{5, 5, 5, kind::dominant}, band_case{10, 2, 5, kind::dominant},
        band_case{64, 0, 3, kind::dominant}, band_case{64, 3, 0, kind::dominant}, band_case{50, 5, 1, kind::dominant},
        band_case{200, 5, 5, kind::dominant}, band_case{500, 1, 1, kind::dominant},  //
        band_case{2, 1, 1, kind::swapped_pairs}, band_case{3, 1, 1, kind::swapped_pairs},
        band_case{4, 3, 2, kind::swapped_pairs}, band_case{5, 2, 2, kind::swapped_pairs},
        band_case{7, 1, 3, kind::swapped_pairs}, band_case{10, 2, 5, kind::swapped_pairs},
        band_case{50, 5, 1, kind::swapped_pairs}, band_case{64, 3, 3, kind::swapped_pairs},
        band_case{200, 5, 5, kind::swapped_pairs}, band_case{301, 4, 2, kind::swapped_pairs},
        band_case{300, 1, 4, kind::swapped_pairs}, band_case{500, 1, 1, kind::swapped_pairs},  //
        band_case{1, 0, 0, kind::random}, band_case{3, 2, 0, kind::random}, band_case{6, 2, 0, kind::random},
        band_case{7, 3, 1, kind::random}, band_case{5, 4, 4, kind::random}, band_case{12, 4, 4, kind::random},
        band_case{20, 1, 1, kind::random}, band_case{30, 2, 5, kind::random, 3}, band_case{40, 5, 2, kind::random, 3},
        band_case{60, 5, 5, kind::random, 8}, band_case{100, 3, 3, kind::random}),
    case_name);

TEST(band_matrix, accessors_match_dense) {
  const band_matrix a = random_band(37, 4, 2, kind::random, 11);
  const MatrixXd d = to_dense(a);
  EXPECT_EQ((d.array() != 0.0).count(), 37 * 7 - 4 * 5 / 2 - 2 * 3 / 2);  // the band less its two corners
  const VectorXd x = random_vector(37, 12);
  const VectorXd y = times(a, x);
  EXPECT_LE((y - d * x).lpNorm<Eigen::Infinity>(), 1e-15 * (d.cwiseAbs() * x.cwiseAbs()).maxCoeff());
}

TEST(band_matrix, assign_combination_forms_the_newton_matrix) {
  const Index n = 30, kl = 3, ku = 5;
  const band_matrix k = random_band(n, kl, ku, kind::random, 21);
  const band_matrix c = random_band(n, kl, ku, kind::random, 22);
  band_matrix a(n, kl, ku);
  const double m = 2.5, h = 0.01;
  a.assign_combination(m, -h, c, -h * h, k);  // M - h dF/dv - h^2 dF/dx
  const MatrixXd expected = m * MatrixXd::Identity(n, n) - h * to_dense(c) - h * h * to_dense(k);
  EXPECT_LE((to_dense(a) - expected).lpNorm<Eigen::Infinity>(), 1e-15);

  // The fill-in rows (the first kl of each column) stay zero.
  const auto s = a.storage();
  for (Index j = 0; j < n; ++j)
    for (Index r = 0; r < kl; ++r) EXPECT_EQ(s[static_cast<std::size_t>(j * (2 * kl + ku + 1) + r)], 0.0);

  // An operand may be the result.
  band_matrix b = c;
  b.assign_combination(1.0, 2.0, b, 0.0, k);
  EXPECT_EQ(to_dense(b), 2.0 * to_dense(c) + MatrixXd::Identity(n, n));
  band_matrix other(n, kl, kl);
  EXPECT_THROW(a.assign_combination(1.0, 1.0, c, 1.0, other), std::invalid_argument);
}

TEST(band_lu, swaps_a_permutation_matrix) {
  band_matrix a(2, 1, 1);
  a(0, 1) = 2.0;
  a(1, 0) = 4.0;
  band_lu lu(2, 1, 1);
  ASSERT_TRUE(lu.factorize(a));
  EXPECT_EQ(lu.pivots()[0], 1);
  VectorXd b(2);
  b << 6.0, 8.0;
  lu.solve_in_place(b);
  EXPECT_EQ(b[0], 2.0);
  EXPECT_EQ(b[1], 3.0);
}

TEST(band_lu, reports_a_singular_matrix) {
  const Index n = 20, kl = 2, ku = 3;
  band_lu lu(n, kl, ku);

  band_matrix zero(n, kl, ku);
  EXPECT_FALSE(lu.factorize(zero));
  EXPECT_EQ(lu.zero_pivot(), 0);
  EXPECT_FALSE(lu.factored());
  VectorXd b = VectorXd::Ones(n);
  EXPECT_THROW(lu.solve_in_place(b), std::logic_error);

  // A zero column stays zero through the elimination: its pivot is exactly zero.
  band_matrix a = random_band(n, kl, ku, kind::swapped_pairs, 31);
  for (Index i = 7 - ku; i <= 7 + kl; ++i) a(i, 7) = 0.0;
  EXPECT_FALSE(lu.factorize(a));
  EXPECT_EQ(lu.zero_pivot(), 7);

  // Two equal rows: the multiplier between them is exactly 1 and their difference exactly zero.
  a = random_band(n, kl, ku, kind::dominant, 32);
  const Index r = 11;  // rows r and r + 1 share columns r + 1 - kl .. r + ku
  a(r, r - kl) = 0.0;
  a(r + 1, r + 1 + ku) = 0.0;
  for (Index j = r + 1 - kl; j <= r + ku; ++j) a(r + 1, j) = a(r, j);
  EXPECT_FALSE(lu.factorize(a));
  EXPECT_GE(lu.zero_pivot(), r);

  // The same object factors a regular matrix afterwards.
  a = random_band(n, kl, ku, kind::dominant, 33);
  EXPECT_TRUE(lu.factorize(a));
  EXPECT_EQ(lu.zero_pivot(), -1);
  lu.solve_in_place(b);
  EXPECT_LT(backward_error(a, b, VectorXd::Ones(n)), 1e-14);
}

TEST(band_lu, rejects_a_shape_other_than_resized) {
  band_lu lu(10, 2, 2);
  EXPECT_THROW(lu.factorize(band_matrix(10, 2, 3)), std::invalid_argument);
  EXPECT_THROW(lu.factorize(band_matrix(11, 2, 2)), std::invalid_argument);
  ASSERT_TRUE(lu.factorize(random_band(10, 2, 2, kind::dominant, 41)));
  VectorXd b = VectorXd::Ones(9);
  EXPECT_THROW(lu.solve_in_place(b), std::invalid_argument);
}

TEST(band_lu, factorize_and_solve_allocate_nothing_after_resize) {
  const Index n = 3 * 4096, kl = 5, ku = 5;
  const band_matrix k = random_band(n, kl, ku, kind::swapped_pairs, 51);
  const band_matrix c = random_band(n, kl, ku, kind::dominant, 52);
  band_matrix a(n, kl, ku);
  band_lu lu(n, kl, ku);
  const VectorXd b = random_vector(n, 53);
  VectorXd x = b;

  const long before = g_allocations.load();
  Eigen::internal::set_is_malloc_allowed(false);  // Eigen asserts on any heap allocation from here
  bool ok = true;
  for (int newton = 0; newton < 3; ++newton) {  // as in a Newton loop: form, factor, solve
    a.assign_combination(1.0, -0.01 * (newton + 1), c, 1.0, k);
    ok = ok && lu.factorize(a);
    x = b;
    lu.solve_in_place(x);
  }
  Eigen::internal::set_is_malloc_allowed(true);
  const long after = g_allocations.load();

  ASSERT_TRUE(ok);
  EXPECT_EQ(after - before, 0);
  EXPECT_GT(interchanges(lu), 0);
  EXPECT_LT(backward_error(a, x, b), 1e-14);
}

// Not an assertion on time: prints the cost at the spring chain's largest size.
TEST(band_lu, timing_at_chain_size) {
  const Index n = 3 * 65536, kl = 5, ku = 5;
  for (const kind k : {kind::dominant, kind::swapped_pairs}) {
    const band_matrix a = random_band(n, kl, ku, k, 61);
    band_lu lu(n, kl, ku);
    const VectorXd b = random_vector(n, 62);
    VectorXd x(n);
    double best_factor = 1e300, best_solve = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
      x = b;
      const auto t0 = std::chrono::steady_clock::now();
      const bool ok = lu.factorize(a);
      const auto t1 = std::chrono::steady_clock::now();
      lu.solve_in_place(x);
      const auto t2 = std::chrono::steady_clock::now();
      ASSERT_TRUE(ok);
      best_factor = std::min(best_factor, std::chrono::duration<double, std::milli>(t1 - t0).count());
      best_solve = std::min(best_solve, std::chrono::duration<double, std::milli>(t2 - t1).count());
    }
    EXPECT_LT(backward_error(a, x, b), 1e-14);
    std::printf(
        "[ timing   ] n = %ld, kl = ku = 5, %s (%ld interchanges): factorize %.2f ms, solve %.2f ms (best of 5)\n",
        static_cast<long>(n), k == kind::dominant ? "diagonally dominant" : "swapped pairs", interchanges(lu),
        best_factor, best_solve);
  }
}

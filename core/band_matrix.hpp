#pragma once
// Banded matrices and their LU factorisation with partial pivoting, for the Newton
// steps of the implicit integrators on a spring chain: the matrix M - h dF/dv - h^2 dF/dx
// couples each coordinate only to its neighbours', so an n x n solve costs
// O(n kl (kl + ku)) instead of O(n^3), and after `resize` nothing is allocated.
//
// Storage is LAPACK's for dgbtrf: column-major, ld = 2 kl + ku + 1 rows per column,
// A(i, j) at row kl + ku + i - j of column j. So column j holds, top to bottom, kl
// fill-in rows, the ku super-diagonal entries A(j - ku .. j - 1, j), the diagonal and
// the kl sub-diagonal entries A(j + 1 .. j + kl, j). The fill-in rows are zero in a
// band_matrix; they are there so the factorisation can work in a copy of the same
// layout: a row interchange at step j brings row j + p (p <= kl) up, and its entries
// reach column j + p + ku, so U gets kl + ku super-diagonals, kl more than A.
//
// Errors: shape checks that cost O(1) per call throw std::invalid_argument (they are
// programming errors, cheap to catch in release builds too); element accessors only
// assert, being in inner loops.
#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

namespace stepbench {

class band_matrix {
 public:
  band_matrix() = default;
  band_matrix(Eigen::Index n, Eigen::Index kl, Eigen::Index ku) { resize(n, kl, ku); }

  // Sizes the storage (the only allocation) and zeroes it.
  void resize(Eigen::Index n, Eigen::Index kl, Eigen::Index ku) {
    if (n < 0 || kl < 0 || ku < 0) throw std::invalid_argument("band_matrix::resize: negative size or bandwidth");
    n_ = n;
    kl_ = kl;
    ku_ = ku;
    ld_ = 2 * kl + ku + 1;
    ab_.assign(static_cast<std::size_t>(ld_ * n), 0.0);
  }

  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  Eigen::Index kl() const { return kl_; }  // sub-diagonals
  Eigen::Index ku() const { return ku_; }  // super-diagonals
  bool same_shape(const band_matrix& o) const { return n_ == o.n_ && kl_ == o.kl_ && ku_ == o.ku_; }

  bool in_band(Eigen::Index i, Eigen::Index j) const {
    return 0 <= i && i < n_ && 0 <= j && j < n_ && j - ku_ <= i && i <= j + kl_;
  }

  void set_zero() { std::fill(ab_.begin(), ab_.end(), 0.0); }

  double& operator()(Eigen::Index i, Eigen::Index j) { return ab_[at(i, j)]; }
  double operator()(Eigen::Index i, Eigen::Index j) const { return ab_[at(i, j)]; }

  // A = c0 I + c1 B1 + c2 B2, all three of one shape (B1 or B2 may be *this): the
  // Newton matrix M - h dF/dv - h^2 dF/dx of an implicit step with scalar mass M.
  // Only the band rows are written, so the fill-in rows stay zero.
  void assign_combination(double c0, double c1, const band_matrix& b1, double c2, const band_matrix& b2) {
    if (!same_shape(b1) || !same_shape(b2))
      throw std::invalid_argument("band_matrix::assign_combination: operands differ in shape");
    const Eigen::Index band_rows = kl_ + ku_ + 1;
    for (Eigen::Index j = 0; j < n_; ++j) {
      const std::size_t first = static_cast<std::size_t>(j * ld_ + kl_);
      double* a = ab_.data() + first;
      const double* p1 = b1.ab_.data() + first;
      const double* p2 = b2.ab_.data() + first;
      for (Eigen::Index r = 0; r < band_rows; ++r) a[r] = c1 * p1[r] + c2 * p2[r];
      a[ku_] += c0;  // the diagonal: row kl + ku of the column
    }
  }

  // The raw band storage, ld * n doubles in the layout described at the top.
  std::span<const double> storage() const { return ab_; }

 private:
  friend class band_lu;  // factors in a copy of this layout
  std::size_t at(Eigen::Index i, Eigen::Index j) const {
    assert(in_band(i, j));
    return static_cast<std::size_t>(j * ld_ + kl_ + ku_ + i - j);
  }

  Eigen::Index n_ = 0;
  Eigen::Index kl_ = 0;
  Eigen::Index ku_ = 0;
  Eigen::Index ld_ = 1;
  std::vector<double> ab_;
};

// P A = L U of a band matrix, and solves with it. The algorithm is Gaussian elimination
// with partial pivoting on a band (Golub & Van Loan, Matrix Computations, sec. 4.3: with
// lower bandwidth p = kl and upper q = ku, U gets upper bandwidth p + q and each Gauss
// vector at most p nonzeros), organised as LAPACK's dgbtf2 (unblocked dgbtrf) documents
// it, and written here from that description: the factors overwrite a copy of A in the
// dgbtrf layout; U, with kl + ku super-diagonals, takes the upper kl + ku + 1 rows and
// the multipliers of L (at most kl per column) the rows below the diagonal. The
// interchanges are applied to L as they happen, not to the multipliers already stored,
// so L is the product P_0 L_0 P_1 L_1 ... and the forward solve (as in dgbtrs) interleaves
// the interchanges with the eliminations.
class band_lu {
 public:
  band_lu() = default;
  band_lu(Eigen::Index n, Eigen::Index kl, Eigen::Index ku) { resize(n, kl, ku); }

  // Allocates the factor storage and the pivots; factorize and solve_in_place allocate nothing.
  void resize(Eigen::Index n, Eigen::Index kl, Eigen::Index ku) {
    if (n < 0 || kl < 0 || ku < 0) throw std::invalid_argument("band_lu::resize: negative size or bandwidth");
    lu_.resize(n, kl, ku);
    ipiv_.assign(static_cast<std::size_t>(n), 0);
    factored_ = false;
    zero_pivot_ = -1;
  }

  // Factors `a`, of the shape given to resize, in O(n kl (kl + ku)) flops. Returns false
  // when a pivot is exactly zero (A is singular); zero_pivot() then gives its column and
  // the factors are unusable. As in dgbtf2, NaN or infinite entries are not looked for:
  // they reach the solution, where the Newton iteration's convergence test sees them.
  bool factorize(const band_matrix& a);

  // b <- A^-1 b with the last successful factorisation, in O(n (2 kl + ku)) flops.
  void solve_in_place(Eigen::Ref<Eigen::VectorXd> b) const;

  bool factored() const { return factored_; }
  // Column of the first exactly zero pivot of the last factorize, or -1 if there was none.
  Eigen::Index zero_pivot() const { return zero_pivot_; }
  // Row interchanges: at step j, row j was swapped with row pivots()[j] (>= j).
  std::span<const Eigen::Index> pivots() const { return ipiv_; }

 private:
  band_matrix lu_;  // the factors, in the layout of A
  std::vector<Eigen::Index> ipiv_;
  bool factored_ = false;
  Eigen::Index zero_pivot_ = -1;
};

inline bool band_lu::factorize(const band_matrix& a) {
  if (!a.same_shape(lu_)) throw std::invalid_argument("band_lu::factorize: matrix shape differs from resize()");
  // The copy brings zero fill-in rows with it (a band_matrix keeps them zero), which
  // the interchanges below rely on.
  std::copy(a.ab_.begin(), a.ab_.end(), lu_.ab_.begin());
  factored_ = false;
  zero_pivot_ = -1;

  const Eigen::Index n = lu_.n_, kl = lu_.kl_, ku = lu_.ku_;
  const Eigen::Index kv = kl + ku;  // row of the diagonal in each column
  const Eigen::Index ld = lu_.ld_;
  double* ab = lu_.ab_.data();
  // Last column reached by the rows interchanged so far: U's row j extends to column
  // j + ku + p after row j + p was swapped up, and the updates must cover it.
  Eigen::Index ju = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    double* cj = ab + j * ld + kv;                    // cj[r] = A(j + r, j), r in [-kv, kl]
    const Eigen::Index km = std::min(kl, n - 1 - j);  // sub-diagonal entries left in column j

    // Pivot: the largest magnitude on or below the diagonal (the first one on ties, as idamax).
    Eigen::Index p = 0;
    double biggest = std::abs(cj[0]);
    for (Eigen::Index r = 1; r <= km; ++r) {
      if (std::abs(cj[r]) > biggest) {
        biggest = std::abs(cj[r]);
        p = r;
      }
    }
    ipiv_[static_cast<std::size_t>(j)] = j + p;
    if (cj[p] == 0.0) {
      zero_pivot_ = j;
      return false;
    }

    ju = std::max(ju, std::min(j + ku + p, n - 1));
    if (p != 0) {
      // Swap rows j and j + p in columns j..ju. A(i, c) is at ab[c * ld + kv + i - c].
      for (Eigen::Index c = j; c <= ju; ++c) std::swap(ab[c * ld + kv + j - c], ab[c * ld + kv + j + p - c]);
    }
    if (km > 0) {
      // Multipliers l(j + r, j) = A(j + r, j) / A(j, j) (a division, not a multiply by
      // the reciprocal: the same cost for km <= kl, and correctly rounded).
      const double pivot = cj[0];
      for (Eigen::Index r = 1; r <= km; ++r) cj[r] /= pivot;
      // Rank-1 update of the trailing block rows j+1..j+km, columns j+1..ju, one column at
      // a time so each column's entries are contiguous.
      for (Eigen::Index c = j + 1; c <= ju; ++c) {
        double* cc = ab + c * ld + kv + j - c;  // cc[r] = A(j + r, c)
        const double u = cc[0];
        if (u == 0.0) continue;
        for (Eigen::Index r = 1; r <= km; ++r) cc[r] -= cj[r] * u;
      }
    }
  }
  factored_ = true;
  return true;
}

inline void band_lu::solve_in_place(Eigen::Ref<Eigen::VectorXd> b) const {
  if (!factored_) throw std::logic_error("band_lu::solve_in_place: no successful factorisation");
  const Eigen::Index n = lu_.n_, kl = lu_.kl_, ku = lu_.ku_;
  if (b.size() != n) throw std::invalid_argument("band_lu::solve_in_place: vector size differs from n");
  const Eigen::Index kv = kl + ku;
  const Eigen::Index ld = lu_.ld_;
  const double* ab = lu_.ab_.data();
  double* x = b.data();  // Ref<VectorXd> has unit inner stride

  // L y = P b: at step j, the interchange of step j, then the elimination with column j's
  // multipliers.
  if (kl > 0) {
    for (Eigen::Index j = 0; j + 1 < n; ++j) {
      const Eigen::Index p = ipiv_[static_cast<std::size_t>(j)];
      if (p != j) std::swap(x[j], x[p]);
      const double xj = x[j];
      if (xj == 0.0) continue;
      const double* l = ab + j * ld + kv;  // l[r] = l(j + r, j)
      const Eigen::Index lm = std::min(kl, n - 1 - j);
      for (Eigen::Index r = 1; r <= lm; ++r) x[j + r] -= l[r] * xj;
    }
  }

  // U x = y, column-oriented: U has kl + ku super-diagonals.
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    const double* u = ab + j * ld + kv - j;  // u[i] = U(i, j), i in [j - kv, j]
    x[j] /= u[j];
    const double xj = x[j];
    if (xj == 0.0) continue;
    for (Eigen::Index i = std::max<Eigen::Index>(0, j - kv); i < j; ++i) x[i] -= u[i] * xj;
  }
}

}  // namespace stepbench

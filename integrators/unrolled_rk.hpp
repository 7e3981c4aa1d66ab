#pragma once
// The stages of an explicit Runge-Kutta method with its Butcher tableau as compile-time
// constants, for the tableau methods (rk45, rk8, dop853). Not a method itself. The same
// stages as the generic engine of the tests (tests/generic_rk.hpp, fed the tableau at run
// time; tests/test_high_order.cpp checks that they agree to rounding), scheduled for
// latency as rk4 is:
//  - every sum is unrolled at compile time and zero coefficients drop out;
//  - 1 / m is folded into the coefficients, V_i = v0 + sum_j (h a_ij / m) F_j;
//  - each sum adds its newest term last, so one multiply-add follows the force (or
//    stage velocity) it waits for: a step's latency is the chain of its stages.
//
// A force that depends on position only (Sys::force_depends_on_velocity false) needs no
// stage velocities. Substituting V_j = v0 + (h/m) sum_k a_jk F_k into
// X_i = x0 + h sum_j a_ij V_j gives the Nystrom form of the same stages (Hairer, Norsett
// & Wanner, Solving ODEs I, 2nd ed., sec. II.14, eq. 14.7-14.8):
//   X_i = x0 + c_i h v0 + (h^2 / m) sum_k (A^2)_ik F_k,   c_i = sum_j a_ij,
// in which X_i waits for F_{i-2} at the latest (A^2 has one more zero subdiagonal), so
// the chains of consecutive stages overlap; and the position of a weighted sum,
// h sum_i w_i V_i = (sum_i w_i) h v0 + (h^2 / m) sum_k (w^T A)_k F_k.
#include <array>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "core/concepts.hpp"
#include "integrators/tableau.hpp"

namespace stepbench {

namespace rk_detail {

// The nonzero entries of a row of coefficients: what an unrolled sum adds.
template <int S>
struct sparse_row {
  std::array<int, S> j{};
  std::array<double, S> w{};
  int n = 0;
};

template <int S>
constexpr sparse_row<S> sparse(const std::array<double, S>& w) {
  sparse_row<S> r{};
  for (int j = 0; j < S; ++j)
    if (w[j] != 0.0) {
      r.j[r.n] = j;
      r.w[r.n] = w[j];
      ++r.n;
    }
  return r;
}

template <int S>
using matrix = std::array<std::array<double, S>, S>;

template <int S>
constexpr matrix<S> square(const matrix<S>& a) {
  matrix<S> r{};
  for (int i = 0; i < S; ++i)
    for (int k = 0; k < S; ++k)
      for (int j = 0; j < S; ++j) r[i][k] += a[i][j] * a[j][k];
  return r;
}

// (w^T A)_k = sum_i w_i a_ik.
template <int S>
constexpr std::array<double, S> times(const std::array<double, S>& w, const matrix<S>& a) {
  std::array<double, S> r{};
  for (int k = 0; k < S; ++k)
    for (int i = 0; i < S; ++i) r[k] += w[i] * a[i][k];
  return r;
}

template <int S>
constexpr double sum(const std::array<double, S>& w) {
  double s = 0.0;
  for (double x : w) s += x;
  return s;
}

// dst = base + sum_k (scale w_k) terms[j_k], in increasing j (the newest term last); with
// no_base, the sum alone (at least one term).
// (Function templates rather than lambdas: GCC's flatten does not always inline a
// generic lambda's call operator.)
// A state of fixed size is summed coefficient by coefficient on plain doubles: the same
// operations in the same order as Eigen's expression (so the same roundings), but a
// sum of a dozen terms as one Eigen expression is a tree of a dozen nodes, which GCC
// keeps on the stack instead of in registers (rk8 on one coordinate: a quarter slower).
struct no_base {};
template <const auto& R, class Dst, class Base, class Terms, std::size_t... K>
[[gnu::always_inline]] inline void assign_sum(Dst& dst, [[maybe_unused]] const Base& base,
                                              [[maybe_unused]] double scale, [[maybe_unused]] const Terms& terms,
                                              std::index_sequence<K...>) {
  constexpr bool fixed = Dst::SizeAtCompileTime != Eigen::Dynamic;
  if constexpr (std::is_same_v<Base, no_base>) {
    static_assert(R.n > 0);
    if constexpr (fixed) {
      for (Eigen::Index i = 0; i < Dst::SizeAtCompileTime; ++i)
        dst.coeffRef(i) = (... + ((scale * R.w[K]) * terms[R.j[K]].coeff(i)));
    } else {
      dst = (... + ((scale * R.w[K]) * terms[R.j[K]]));
    }
  } else if constexpr (fixed) {
    for (Eigen::Index i = 0; i < Dst::SizeAtCompileTime; ++i)
      dst.coeffRef(i) = (base.coeff(i) + ... + ((scale * R.w[K]) * terms[R.j[K]].coeff(i)));
  } else {
    dst = (base + ... + ((scale * R.w[K]) * terms[R.j[K]]));
  }
}
template <const auto& R, class Dst, class Base, class Terms>
[[gnu::always_inline]] inline void assign_sum(Dst& dst, const Base& base, double scale, const Terms& terms) {
  assign_sum<R>(dst, base, scale, terms, std::make_index_sequence<static_cast<std::size_t>(R.n)>{});
}

}  // namespace rk_detail

// The constant tables derived from a tableau T (an explicit_tableau<S> with static
// storage), computed once at compile time.
template <const auto& T>
struct rk_tables {
  static constexpr int S = std::remove_cvref_t<decltype(T)>::stages;
  static constexpr rk_detail::matrix<S> a2 = rk_detail::square<S>(T.a);
  template <int I>
  static constexpr auto a_row = rk_detail::sparse<S>(T.a[I]);
  template <int I>
  static constexpr auto a2_row = rk_detail::sparse<S>(a2[I]);
  template <int I>
  static constexpr double row_sum = rk_detail::sum<S>(T.a[I]);
};

// Weights W (a std::array<double, S> with static storage) applied to the stages of T:
// their sparse forms for the velocity sums and the Nystrom position sums.
template <const auto& T, const auto& W>
struct rk_weights {
  static constexpr int S = rk_tables<T>::S;
  static constexpr auto row = rk_detail::sparse<S>(W);
  static constexpr std::array<double, S> wa = rk_detail::times<S>(W, T.a);
  static constexpr auto wa_row = rk_detail::sparse<S>(wa);
  static constexpr double total = rk_detail::sum<S>(W);
};

// Nystrom: the Nystrom form, no stage velocities (by default for a position-only force).
template <const auto& T, class Sys, bool Nystrom = !Sys::force_depends_on_velocity>
struct unrolled_rk {
  using Vec = typename Sys::vec;
  using tables = rk_tables<T>;
  static constexpr int S = tables::S;
  static constexpr bool nystrom = Nystrom;

  std::array<Vec, S> V, F;  // stage velocities (not formed in the Nystrom form) and forces
  Vec X;                    // position of the stage being formed

  void resize(const Vec& like) {
    for (auto& v : V) size_like(like, v);
    for (auto& f : F) size_like(like, f);
    size_like(like, X);
  }

  // Stages First..Last-1 from (x0, v0) at t with step h (h_im = h / m). F[0] must be set;
  // from First = 1 the velocity form sets V[0] = v0, otherwise every stage before First
  // must be complete. Form selects the form (default: the stepper's).
  template <int First, int Last, bool Form = nystrom>
  [[gnu::always_inline]] inline void compute(const Sys& sys, double t, const Vec& x0, const Vec& v0, double h,
                                             double h_im) {
    const double hh_im = h * h_im;
    if constexpr (!Form && First == 1) V[0] = v0;
    stages<First, Form>(sys, t, x0, v0, h, h_im, hh_im, std::make_integer_sequence<int, Last - First>{});
  }

  template <int First, bool Form, int... I>
  [[gnu::always_inline]] inline void stages(const Sys& sys, double t, const Vec& x0, const Vec& v0, double h,
                                            double h_im, double hh_im, std::integer_sequence<int, I...>) {
    (stage<First + I, Form>(sys, t, x0, v0, h, h_im, hh_im), ...);
  }

  template <int I, bool Form>
  [[gnu::always_inline]] inline void stage(const Sys& sys, double t, const Vec& x0, const Vec& v0, double h,
                                           double h_im, double hh_im) {
    using R = tables;
    if constexpr (Form) {
      rk_detail::assign_sum<R::template a2_row<I>>(X, x0 + (R::template row_sum<I> * h) * v0, hh_im, F);
      sys.force(t + T.c[I] * h, X, v0, F[I]);  // v is not read by a position-only force
    } else {
      rk_detail::assign_sum<R::template a_row<I>>(X, x0, h, V);
      rk_detail::assign_sum<R::template a_row<I>>(V[I], v0, h_im, F);
      sys.force(t + T.c[I] * h, X, V[I], F[I]);
    }
  }

  // x = x0 + h sum_i W_i V_i, v = v0 + (h/m) sum_i W_i F_i (in the Nystrom form the
  // position from the forces). x0, v0 may alias x, v: x is written first, from v0.
  template <const auto& W>
  [[gnu::always_inline]] inline void combine(Vec& x, Vec& v, const Vec& x0, const Vec& v0, double h, double h_im) {
    using w = rk_weights<T, W>;
    if constexpr (nystrom)
      rk_detail::assign_sum<w::wa_row>(x, x0 + (w::total * h) * v0, h * h_im, F);
    else
      rk_detail::assign_sum<w::row>(x, x0, h, V);
    rk_detail::assign_sum<w::row>(v, v0, h_im, F);
  }

  // The same for weights known at run time (dense output), every stage velocity formed:
  // x = x0 + h sum_i w_i V_i, v = v0 + (h/m) sum_i w_i F_i.
  void combine(const std::array<double, S>& w, double h, double h_im, const Vec& x0, const Vec& v0, Vec& x,
               Vec& v) const {
    x = x0;
    v = v0;
    for (int i = 0; i < S; ++i) {
      if (w[i] == 0.0) continue;
      x += (h * w[i]) * V[i];
      v += (h_im * w[i]) * F[i];
    }
  }

  // The same sums without the starting state, for weights that sum to zero (an error
  // estimate b - b_hat): x = h sum_i W_i V_i, v = (h/m) sum_i W_i F_i.
  template <const auto& W>
  [[gnu::always_inline]] inline void difference(Vec& x, Vec& v, const Vec& v0, double h, double h_im) {
    using w = rk_weights<T, W>;
    if constexpr (nystrom) {
      if constexpr (w::total == 0.0)
        rk_detail::assign_sum<w::wa_row>(x, rk_detail::no_base{}, h * h_im, F);
      else  // the weights sum to zero only up to their rounding
        rk_detail::assign_sum<w::wa_row>(x, (w::total * h) * v0, h * h_im, F);
    } else {
      rk_detail::assign_sum<w::row>(x, rk_detail::no_base{}, h, V);
    }
    rk_detail::assign_sum<w::row>(v, rk_detail::no_base{}, h_im, F);
  }

  // V_i = v0 + (h/m) sum_j a_ij F_j for stages First..Last-1 (the stage velocities the
  // Nystrom form skipped, when dense output needs them).
  template <int First, int Last>
  void velocities(const Vec& v0, double h_im) {
    velocities<First>(v0, h_im, std::make_integer_sequence<int, Last - First>{});
  }
  template <int First, int... I>
  void velocities(const Vec& v0, double h_im, std::integer_sequence<int, I...>) {
    (rk_detail::assign_sum<tables::template a_row<First + I>>(V[First + I], v0, h_im, F), ...);
  }
};

}  // namespace stepbench

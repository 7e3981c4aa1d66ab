#pragma once
// Method coefficients as data: an explicit Runge-Kutta method is its Butcher tableau
// (Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., sec. II.1),
//   k_i = f(t + c_i h, y + h sum_{j<i} a_ij k_j),   y_1 = y + h sum_i b_i k_i,
// with optional embedded weights b_hat for an error estimate y_1 - y_hat_1 of lower
// order; a composition of velocity Verlet is its list of sub-step weights. The
// coefficient sets themselves are in integrators/tableaus.hpp, proved in
// tests/test_tableaus.cpp. Everything here is constexpr and allocates nothing.
#include <array>
#include <complex>

namespace stepbench {

template <int S>
struct explicit_tableau {
  static constexpr int stages = S;
  std::array<std::array<double, S>, S> a{};  // strictly lower triangular
  std::array<double, S> b{};
  std::array<double, S> c{};
  int order = 0;
  std::array<double, S> b_hat{};  // an embedded pair's second weights (embedded_order > 0)
  int embedded_order = 0;
};

// The leading S stages of a T-stage tableau: a method stored together with the extra
// stages of its dense output (DOP853) is written once, as the larger table. Only valid
// when b and b_hat vanish beyond stage S (the extra stages do not enter the step).
template <int S, int T>
constexpr explicit_tableau<S> leading_stages(const explicit_tableau<T>& t) {
  static_assert(S <= T);
  explicit_tableau<S> r{};
  for (int i = 0; i < S; ++i) {
    for (int j = 0; j < S; ++j) r.a[i][j] = t.a[i][j];
    r.b[i] = t.b[i];
    r.c[i] = t.c[i];
    r.b_hat[i] = t.b_hat[i];
  }
  r.order = t.order;
  r.embedded_order = t.embedded_order;
  return r;
}

// Stability function R(z) = 1 + z b^T (I - z A)^{-1} 1: the step y_1 = R(h lambda) y_0
// on y' = lambda y (Hairer & Wanner, Solving ODEs II, 2nd ed., sec. IV.2).
// For explicit A the system (I - z A) g = 1 is lower triangular with unit diagonal, so
// g is a forward substitution: g_i = 1 + z sum_{j<i} a_ij g_j (g_i is the i-th stage
// value divided by y_0).
template <int S>
constexpr std::complex<double> stability_function(const explicit_tableau<S>& t, std::complex<double> z) {
  std::array<std::complex<double>, S> g{};
  std::complex<double> bg = 0.0;
  for (int i = 0; i < S; ++i) {
    std::complex<double> s = 0.0;
    for (int j = 0; j < i; ++j) s += t.a[i][j] * g[j];
    g[i] = 1.0 + z * s;
    bg += t.b[i] * g[i];
  }
  return 1.0 + z * bg;
}

// A symmetric composition of velocity Verlet (kick-drift-kick, order 2):
//   Psi_h = VV_{w_N h} o ... o VV_{w_1 h}   (Yoshida, Phys. Lett. A 150 (1990) 262;
// Hairer, Lubich & Wanner, Geometric Numerical Integration, 2nd ed., sec. II.4, V.3). Consistency
// needs sum w_i = 1; w palindromic keeps the composition symmetric (even order).
template <int N>
struct verlet_composition {
  std::array<double, N> w{};
  int order = 0;
};

// The same method as a position-velocity splitting: for i = 0..N-1,
//   v += kick[i] h a(x),  x += drift[i] h v,   then finally  v += kick[N] h a(x).
// VV_{w h} is kick w/2, drift w, kick w/2, and the two kicks between adjacent sub-steps
// act at the same x, so they merge: kick[0] = w_1/2, kick[i] = (w_i + w_{i+1})/2,
// kick[N] = w_N/2, drift[i] = w_{i+1}. With a position-only force, kick[N] of one step
// and kick[0] of the next use the same a(x): N force evaluations per step.
template <int N>
struct kick_drift_sequence {
  std::array<double, N + 1> kick{};
  std::array<double, N> drift{};
};

template <int N>
constexpr kick_drift_sequence<N> kick_drift(const verlet_composition<N>& m) {
  kick_drift_sequence<N> s{};
  s.kick[0] = 0.5 * m.w[0];
  for (int i = 0; i < N; ++i) {
    s.drift[i] = m.w[i];
    s.kick[i + 1] = 0.5 * (m.w[i] + (i + 1 < N ? m.w[i + 1] : 0.0));
  }
  return s;
}

}  // namespace stepbench

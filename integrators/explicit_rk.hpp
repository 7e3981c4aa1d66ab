#pragma once
// The stages of an explicit Runge-Kutta method, fed its Butcher tableau as data (as
// Odeint's explicit_generic_rk is), in the second-order form the integrators see:
// y = [x; v], f(y) = [v; F / m], so a stage k_i = [V_i; F_i / m] is kept as the stage
// velocity V_i and the stage force F_i, with 1 / m folded into the coefficients.
//   X_i = x0 + h sum_{j<i} a_ij V_j,  V_i = v0 + (h/m) sum_{j<i} a_ij F_j,
//   F_i = F(t + c_i h, X_i, V_i).
// Not a method itself: rk45 uses it, and tests check that the hand-scheduled steps of
// midpoint and rk4 equal the generic step on their tableaux to rounding.
#include <array>

#include "core/concepts.hpp"
#include "integrators/tableau.hpp"

namespace stepbench {

template <int S, class Sys>
struct rk_stages {
  using Vec = typename Sys::vec;
  std::array<Vec, S> V, F;  // stage velocities and forces
  Vec X;                    // position of the stage being formed

  void resize(const Vec& like) {
    for (auto& v : V) size_like(like, v);
    for (auto& f : F) size_like(like, f);
    size_like(like, X);
  }

  // Stage 0 from (v0, f0), then stages 1..S-1. After the call X and V[S-1] hold the
  // last stage's state (for a first-same-as-last method, the new state).
  void compute(const explicit_tableau<S>& tab, const Sys& sys, double t, const Vec& x0, const Vec& v0, const Vec& f0,
               double h) {
    const double h_im = h * inverse_mass(sys);
    V[0] = v0;
    F[0] = f0;
    for (int i = 1; i < S; ++i) {
      X = x0;
      V[i] = v0;
      for (int j = 0; j < i; ++j) {
        if (tab.a[i][j] == 0.0) continue;
        X += (h * tab.a[i][j]) * V[j];
        V[i] += (h_im * tab.a[i][j]) * F[j];
      }
      sys.force(t + tab.c[i] * h, X, V[i], F[i]);
    }
  }

  // x = x0 + h sum_i w_i V_i,  v = v0 + (h/m) sum_i w_i F_i.
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
  // The same sums without the starting state: h sum_i w_i k_i (an error estimate).
  void weighted(const std::array<double, S>& w, double h, double h_im, Vec& x, Vec& v) const {
    x.setZero();
    v.setZero();
    combine(w, h, h_im, x, v, x, v);
  }
};

// b - b_hat: the weights of the embedded error estimate.
template <int S>
constexpr std::array<double, S> error_weights(const explicit_tableau<S>& t) {
  std::array<double, S> e{};
  for (int i = 0; i < S; ++i) e[i] = t.b[i] - t.b_hat[i];
  return e;
}

}  // namespace stepbench

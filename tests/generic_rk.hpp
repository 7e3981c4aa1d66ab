#pragma once
// The stages of an explicit Runge-Kutta method, fed its Butcher tableau as data (as
// Odeint's explicit_generic_rk is), in the second-order form the integrators see:
// y = [x; v], f(y) = [v; F / m], so a stage k_i = [V_i; F_i / m] is kept as the stage
// velocity V_i and the stage force F_i, with 1 / m folded into the coefficients.
//   X_i = x0 + h sum_{j<i} a_ij V_j,  V_i = v0 + (h/m) sum_{j<i} a_ij F_j,
//   F_i = F(t + c_i h, X_i, V_i).
// The tests' reference: the hand-scheduled steps of midpoint and rk4 and the unrolled
// stages of integrators/unrolled_rk.hpp (rk45, rk8, dop853) equal it to rounding.
#include <array>

#include "core/concepts.hpp"
#include "integrators/tableau.hpp"
#include "integrators/unrolled_rk.hpp"

namespace stepbench {

// A tableau of S stages to lend unrolled_rk's storage (V, F, X, resize) and its combine
// with weights given at run time; its own stages are not used.
template <int S>
inline constexpr explicit_tableau<S> no_tableau{};

template <int S, class Sys>
struct rk_stages : unrolled_rk<no_tableau<S>, Sys, false> {
  using Vec = typename Sys::vec;
  using base = unrolled_rk<no_tableau<S>, Sys, false>;
  using base::V, base::F, base::X;

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
};

}  // namespace stepbench

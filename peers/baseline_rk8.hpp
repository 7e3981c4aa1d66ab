#pragma once
// Hand-written eighth-order Runge-Kutta (DOP853's 12-stage step, integrators/tableaus.hpp)
// on plain doubles: the speed-of-light baseline of rk8, for scale only (origin
// "baseline", like baseline_rk4). One scalar degree of freedom, the acceleration with the
// problem's constants folded (peers/baseline_rk4.hpp), no Eigen, no counting wrapper;
// the loops over the constant tableau are unrolled by the compiler, which folds the
// coefficients and drops the zero ones. The same latency ordering as ours: every sum
// adds its newest term last, and for a position-only acceleration (the pendulum) the
// stage positions come from the accelerations directly (the Nystrom form,
// integrators/unrolled_rk.hpp), so that consecutive stages overlap.

#include "core/method.hpp"
#include "integrators/tableaus.hpp"
#include "integrators/unrolled_rk.hpp"
#include "peers/baseline_rk4.hpp"

namespace stepbench::peers {

struct baseline_rk8 {
  static method_info describe() {
    return {.name = "baseline_rk8",
            .description =
                "hand-written eighth-order RK (the DOP853 step) on plain doubles, fully inlined: the speed-of-light "
                "step, for scale",
            .origin = method_origin::baseline,
            .declared_order = 8.0,
            .evals_per_step = 12.0,
            .library = "hand-written"};
  }
  template <problem P>
  static constexpr bool applies = has_baseline<P>;

  template <problem P>
  struct adapter : scalar_baseline_state<P> {
    using scalar_baseline_state<P>::scalar_baseline_state;
    [[gnu::always_inline]] void step(double, double h) {
      baseline_rk8::step<P::force_depends_on_velocity>(this->x, this->v, h, this->accel);
      this->evals += 12;
    }
  };

  // One step of h from (x, v).
  template <bool Velocity, class Accel>
  [[gnu::always_inline]] static inline void step(double& x, double& v, double h, const Accel& accel) {
    constexpr auto& tab = dop853_tableau;
    constexpr auto& a2 = rk_tables<dop853_tableau>::a2;
    constexpr auto& ba = rk_weights<dop853_tableau, dop853_tableau.b>::wa;
    double a[12], vs[12];
    a[0] = accel(x, v);
    vs[0] = v;
    const double hh = h * h;
#pragma GCC unroll 12
    for (int i = 1; i < 12; ++i) {
      double xi = x, vi = v;
      if constexpr (Velocity) {
#pragma GCC unroll 12
        for (int j = 0; j < i; ++j)
          if (tab.a[i][j] != 0.0) xi += (h * tab.a[i][j]) * vs[j];
#pragma GCC unroll 12
        for (int j = 0; j < i; ++j)
          if (tab.a[i][j] != 0.0) vi += (h * tab.a[i][j]) * a[j];
        vs[i] = vi;
      } else {
        double c = 0.0;
#pragma GCC unroll 12
        for (int j = 0; j < i; ++j) c += tab.a[i][j];
        xi += (c * h) * v;
#pragma GCC unroll 12
        for (int j = 0; j < i; ++j)
          if (a2[i][j] != 0.0) xi += (hh * a2[i][j]) * a[j];
      }
      a[i] = accel(xi, vi);
    }
    double x1 = x, v1 = v;
    if constexpr (Velocity) {
#pragma GCC unroll 12
      for (int i = 0; i < 12; ++i)
        if (tab.b[i] != 0.0) x1 += (h * tab.b[i]) * vs[i];
    } else {
      double total = 0.0;
#pragma GCC unroll 12
      for (int i = 0; i < 12; ++i) total += tab.b[i];
      x1 += (total * h) * v;
#pragma GCC unroll 12
      for (int i = 0; i < 12; ++i)
        if (ba[i] != 0.0) x1 += (hh * ba[i]) * a[i];
    }
#pragma GCC unroll 12
    for (int i = 0; i < 12; ++i)
      if (tab.b[i] != 0.0) v1 += (h * tab.b[i]) * a[i];
    x = x1;
    v = v1;
  }
};

}  // namespace stepbench::peers

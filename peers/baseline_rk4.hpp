#pragma once
// Hand-written RK4 on plain doubles: the speed-of-light baseline, for scale only (it is
// a timing floor, not a method a user could pick for any scene: origin "baseline").
// The best a programmer can write for one scalar degree of freedom: the acceleration
// spelled out with constants folded, no abstraction, no Eigen, no counting wrapper, the
// same latency ordering as ours. Same recording of samples as our loop, so the
// comparison is of the step alone.
#include <cmath>
#include <string_view>
#include <utility>

#include "core/method.hpp"
#include "core/step_adapter.hpp"

namespace stepbench::peers {

// The acceleration spelled out with the problem's constants folded and copied into
// locals first, as a programmer writing one scalar loop by hand would: a = -(k/m) x -
// (c/m) v, no division, no separate multiplication by 1/m. (Constants read from the
// problem inside the loop would be reloaded every stage: the loop stores samples, which
// the compiler must assume could alias the problem.) Each is written for one problem,
// chosen by its name, so that this header includes no problem (an edit to a problem
// rebuilds its own units, not every peer's).
template <problem P>
requires(P::name == std::string_view("damped_spring")) auto baseline_acceleration(const P& p) {
  return [km = p.k_s / p.mass_kg, cm = p.k_d / p.mass_kg](double x, double v) { return -cm * v - km * x; };
}
template <problem P>
requires(P::name == std::string_view("pendulum")) auto baseline_acceleration(const P& p) {
  return [g_over_l = p.gravity / p.length_m](double x, double) { return -g_over_l * std::sin(x); };
}

template <class P>
concept has_baseline = requires(const P& p) {
  baseline_acceleration(p)(0.0, 0.0);
};

// What every baseline's step adapter holds: one scalar degree of freedom (x, v), the
// acceleration with the problem's constants folded, and the force evaluations counted
// per step (a register increment, not a counting wrapper).
template <problem P>
struct scalar_baseline_state {
  decltype(baseline_acceleration(std::declval<const P&>())) accel;
  double x, v;
  long evals = 0;
  explicit scalar_baseline_state(const P& p)
      : accel(baseline_acceleration(p)), x(p.initial().x[0]), v(p.initial().v[0]) {}
  template <class Vec>
  void state_into(Vec& xo, Vec& vo) const {
    xo = Vec(x);
    vo = Vec(v);
  }
  long force_evals() const { return evals; }
};

// The descriptor and the step adapter (registered as fixed_step_peer<baseline_rk4>,
// core/step_adapter.hpp, whose loop flattens the step into it).
struct baseline_rk4 {
  static method_info describe() {
    return {.name = "baseline_rk4",
            .description = "hand-written RK4 on plain doubles, fully inlined: the speed-of-light step, for scale",
            .origin = method_origin::baseline,
            .declared_order = 4.0,
            .evals_per_step = 4.0,
            .library = "hand-written"};
  }
  template <problem P>
  static constexpr bool applies = has_baseline<P>;

  template <problem P>
  struct adapter : scalar_baseline_state<P> {
    using scalar_baseline_state<P>::scalar_baseline_state;
    [[gnu::always_inline]] void step(double, double h) {
      auto& [accel, x, v, evals] = *this;
      const double h2 = 0.5 * h;
      const double a1 = accel(x, v);
      const double x2 = x + h2 * v, v2 = v + h2 * a1, a2 = accel(x2, v2);
      const double x3 = x + h2 * v2, v3 = v + h2 * a2, a3 = accel(x3, v3);
      const double x4 = x + h * v3, v4 = v + h * a3;
      // Partial sums first, so one multiply-add follows the last acceleration (as in ours).
      const double w = h / 6.0, x_123 = x + w * (v + 2.0 * (v2 + v3)), v_123 = v + w * (a1 + 2.0 * (a2 + a3));
      const double a4 = accel(x4, v4);
      x = x_123 + w * v4;
      v = v_123 + w * a4;
      evals += 4;
    }
  };
};

}  // namespace stepbench::peers

#pragma once
// Hand-written RK4 on plain doubles: the speed-of-light baseline, for scale only (it is
// a timing floor, not a method a user could pick for any scene: origin "baseline").
// The best a programmer can write for one scalar degree of freedom: the acceleration
// spelled out with constants folded, no abstraction, no Eigen, no counting wrapper, the
// same latency ordering as ours. Same recording of samples as our loop, so the
// comparison is of the step alone.
#include <cmath>
#include <span>

#include "core/drive.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"
#include "problems/damped_spring.hpp"
#include "problems/pendulum.hpp"

namespace stepbench::peers {

// The acceleration spelled out with the problem's constants folded and copied into
// locals first, as a programmer writing one scalar loop by hand would: a = -(k/m) x -
// (c/m) v, no division, no separate multiplication by 1/m. (Constants read from the
// problem inside the loop would be reloaded every stage: the loop stores samples, which
// the compiler must assume could alias the problem.)
inline auto baseline_acceleration(const damped_spring& p) {
  return [km = p.k_s / p.mass_kg, cm = p.k_d / p.mass_kg](double x, double v) { return -cm * v - km * x; };
}
inline auto baseline_acceleration(const pendulum& p) {
  return [g_over_l = p.gravity / p.length_m](double x, double) { return -g_over_l * std::sin(x); };
}

// The loop every baseline shares: one scalar degree of freedom (x, v) stepped by `step`
// on the fixed-step loop (core/drive.hpp), samples recorded, a non-finite state stopping
// the run. Inlined into each baseline's flattened run, so it adds nothing to the step.
template <class Vec, class Step>
[[gnu::always_inline]] inline drive_result<Vec> run_scalar_baseline(double& x, double& v, double dt, double horizon,
                                                                    std::span<const record_point> plan,
                                                                    long force_evals_per_step, Step&& step) {
  drive_result<Vec> out;
  out.start(1, plan.size());
  const loop_end end = fixed_step_loop(
      dt, horizon, plan, step, [](double) {},
      [&](double t) {
        if (!std::isfinite(x) || !std::isfinite(v)) return out.non_finite = true, false;
        out.record(t, Vec(x), Vec(v));
        return true;
      });
  out.steps = end.steps;
  out.t_final = end.t;
  out.work.force_evals = force_evals_per_step * end.steps;
  out.non_finite = out.non_finite || !std::isfinite(x) || !std::isfinite(v);
  out.final_state = {Vec(x), Vec(v)};
  return out;
}

struct baseline_rk4 {
  static method_info info() {
    return {.name = "baseline_rk4",
            .description = "hand-written RK4 on plain doubles, fully inlined: the speed-of-light step, for scale",
            .origin = method_origin::baseline,
            .kind = method_kind::fixed_step,
            .declared_order = 4.0,
            .library = "hand-written"};
  }
  template <problem P>
  static constexpr bool applies = requires(const P& p) {
    baseline_acceleration(p)(0.0, 0.0);
  };

  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return run(p, dt, horizon, plan); };
  }

  template <problem P>
  STEPBENCH_FLATTEN static drive_result<typename P::vec> run(const P& p, double dt, double horizon,
                                                             std::span<const record_point> plan) {
    using vec = typename P::vec;
    const auto accel = baseline_acceleration(p);
    const auto s0 = p.initial();
    double x = s0.x[0], v = s0.v[0];
    return run_scalar_baseline<vec>(x, v, dt, horizon, plan, 4, [&](double, double h) {
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
    });
  }
};

}  // namespace stepbench::peers

#pragma once
// DOP853, adaptive: the explicit Runge-Kutta method of order 8 of Dormand & Prince with
// error estimators of orders 5 and 3 and a dense output of order 7 (Hairer, Norsett &
// Wanner, Solving ODEs I, 2nd ed. (HNW I), sec. II.6 and II.10; Hairer's dop853.f).
// Coefficients from integrators/tableaus.hpp (dop853_extended), proved in
// tests/test_tableaus.cpp; the stages are integrators/unrolled_rk.hpp's.
//  - Step: 12 stages; on acceptance f(t + h, y_1) is evaluated, the next step's first
//    stage (12 evaluations a step, as dop853.f).
//  - Error: dop853.f's, O(h^8) (tableaus.hpp above dop853_err3_weight; error() below).
//    The step-size control is dop853.f's with its defaults
//    (integrators/step_control.hpp: no PI term, beta = 0): h_new = h / clamp(err^(1/8) /
//    0.9, 1/6, 1/0.333), after a rejection h / min(1/0.333, err^(1/8) / 0.9), and no
//    growth right after a rejection.
//  - Dense output of order 7 for the sample times, interpolated inside the steps. Its
//    three extra stages cost three evaluations, paid only in a step that holds a sample
//    time (computed at the first interpolation inside the step, not at every step as
//    dop853.f does when dense output is requested).
#include <array>
#include <cmath>

#include "core/concepts.hpp"
#include "integrators/step_control.hpp"
#include "integrators/tableaus.hpp"
#include "integrators/unrolled_rk.hpp"

namespace stepbench {

// e3 = b - b_hat3 over the 16 stages of dop853_extended (zero beyond stage 12).
inline constexpr std::array<double, 16> dop853_e3 = [] {
  std::array<double, 16> e{};
  for (int i = 0; i < 12; ++i) e[i] = dop853_extended.b[i] - dop853_b_hat3[i];
  return e;
}();

struct dop853 {
  static constexpr std::string_view name = "dop853";
  static constexpr std::string_view description = "Dormand-Prince 8(5,3) (DOP853), 7th-order dense output";
  static constexpr int order = 8;
  static constexpr capabilities traits{.reuses_last_force = true, .error_estimate = true, .dense_output = true};
  static constexpr int force_evals_per_step = 12;
  double tol = 1e-6;
  explicit dop853(double tolerance) : tol(tolerance) {}

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    double tol;
    // dop853.f's controller with its default constants (SAFE = 0.9, FAC1 = 0.333, FAC2 = 6, BETA = 0).
    step_controller control{
        .error_order = 7, .min_factor = 0.333, .max_factor = 6.0, .form = step_controller::rounding::quotient};
    unrolled_rk<dop853_extended, Sys> k;
    Vec x1, v1, ex5, ev5, ex3, ev3, rx, rv;  // new state, error estimates, reciprocal scales
    // The last accepted step, for dense output.
    Vec x0, v0;
    const Sys* sys_last = nullptr;
    double t_last = 0.0, h_last = 0.0, h_im_last = 0.0;
    bool dense_ready = false;

    explicit stepper(const dop853& m) : tol(m.tol) {}
    void resize(const Sys&, const Vec& like) {
      k.resize(like);
      size_like(like, x1, v1, ex5, ev5, ex3, ev3, rx, rv, x0, v0);
    }

    double initial_dt(const Sys& sys, double t, step_state<Vec>& s, double horizon) {
      return starting_step(sys, t, s, order, tol, horizon, x1, v1, ex5);
    }

    step_attempt try_step(const Sys& sys, double t, step_state<Vec>& s, double h) {
      const double h_im = h * inverse_mass(sys);
      k.F[0] = current_force(sys, t, s);
      k.template compute<1, 12>(sys, t, s.x, s.v, h, h_im);
      k.template combine<dop853_extended.b>(x1, v1, s.x, s.v, h, h_im);
      k.template difference<dop853_e5>(ex5, ev5, s.v, h, h_im);
      k.template difference<dop853_e3>(ex3, ev3, s.v, h, h_im);
      return control.attempt(h, error(s), [&] {
        x0 = s.x;
        v0 = s.v;
        sys_last = &sys;
        t_last = t;
        h_last = h;
        h_im_last = h_im;
        dense_ready = false;
        s.x = x1;
        s.v = v1;
        sys.force(t + h, s.x, s.v, s.f);  // the next step's first stage, and stage 13 of the dense output
        s.f_current = true;
        k.F[12] = s.f;
      });
    }

    // dop853.f's err (after label 35): with the components of [x; v] scaled by
    // sc = tol + tol max(|y0|, |y1|), E5 = ||sum e5_i k_i / sc||^2, E3 the same with
    // e3 = b - b_hat3, over n = 2 dim components, err = |h| E5 / sqrt(n (E5 + 0.01 E3));
    // ex, ev include the factor h.
    double error(const step_state<Vec>& s) {
      // One division per component: the reciprocal scales, then products.
      rx = (tol + tol * s.x.cwiseAbs().cwiseMax(x1.cwiseAbs()).array()).inverse().matrix();
      rv = (tol + tol * s.v.cwiseAbs().cwiseMax(v1.cwiseAbs()).array()).inverse().matrix();
      const double e5 = (ex5.array() * rx.array()).square().sum() + (ev5.array() * rv.array()).square().sum();
      const double e3 = (ex3.array() * rx.array()).square().sum() + (ev3.array() * rv.array()).square().sum();
      double deno = e5 + dop853_err3_weight * e3;
      if (!(deno > 0.0)) deno = 1.0;
      return e5 / std::sqrt(static_cast<double>(2 * s.x.size()) * deno);
    }

    // The state at t_n + theta h of the last accepted step (0 <= theta <= 1), from the
    // order-7 continuous extension (dop853_dense_weights over the 16 stages).
    void interpolate(double theta, Vec& x, Vec& v) {
      if (!dense_ready) {
        // Stage velocities from the forces (the Nystrom form does not keep them), then
        // the three extra stages 14-16 in the velocity form.
        // (Row 13 of dop853_extended is b: stage 13 is the new state, its velocity v1.)
        if constexpr (unrolled_rk<dop853_extended, Sys>::nystrom)
          k.template velocities<0, 13>(v0, h_im_last);
        else
          k.V[12] = v1;
        k.template compute<13, 16, false>(*sys_last, t_last, x0, v0, h_last, h_im_last);
        dense_ready = true;
      }
      k.combine(dop853_dense_weights(theta), h_last, h_im_last, x0, v0, x, v);
    }
  };
};

}  // namespace stepbench

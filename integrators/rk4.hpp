#pragma once
// Classic fourth-order Runge-Kutta, in the lecture's form (integration): state
// {x, v}, derivative {dx, dv} = {v, F/m}; each sample takes an Euler sub-step from the
// start with the previous sample's derivative:
//   k1 = f(t, y),  k2 = f(t + dt/2, y + dt/2 k1),  k3 = f(t + dt/2, y + dt/2 k2),
//   k4 = f(t + dt, y + dt k3),  y += dt (k1 + 2 (k2 + k3) + k4) / 6.
// The velocity increments use the forces with 1/m folded into the coefficient
// (v + (h/m) F): the same method, one multiplication less per stage on the chain.
#include "core/concepts.hpp"

namespace stepbench {

struct rk4 {
  static constexpr std::string_view name = "rk4";
  static constexpr std::string_view description = "classic fourth-order Runge-Kutta";
  static constexpr int order = 4;
  static constexpr capabilities traits{};
  static constexpr int force_evals_per_step = 4;

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    Vec x2, v2, f2, x3, v3, f3, x4, v4, f4, x_123, v_123;
    explicit stepper(const rk4&) {}
    void resize(const Sys&, const Vec& like) { size_like(like, x2, v2, f2, x3, v3, f3, x4, v4, f4, x_123, v_123); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double h = 0.5 * dt, im = inverse_mass(sys), h_im = h * im, dt_im = dt * im;
      // The dx of each sample is the velocity of the previous sub-step.
      const Vec& f1 = current_force(sys, t, s);
      x2 = s.x + h * s.v;
      v2 = s.v + h_im * f1;
      sys.force(t + h, x2, v2, f2);
      x3 = s.x + h * v2;
      v3 = s.v + h_im * f2;
      sys.force(t + h, x3, v3, f3);
      x4 = s.x + dt * v3;
      v4 = s.v + dt_im * f3;
      // The weighted sums of the first three samples are formed while the fourth force is
      // being computed, so only one multiply-add follows f4 on the step's critical path.
      const double w = dt / 6.0, w_im = dt_im / 6.0;
      x_123 = s.x + w * (s.v + 2.0 * (v2 + v3));
      v_123 = s.v + w_im * (f1 + 2.0 * (f2 + f3));
      sys.force(t + dt, x4, v4, f4);
      s.x = x_123 + w * v4;
      s.v = v_123 + w_im * f4;
      s.f_current = false;
    }
  };
};

}  // namespace stepbench

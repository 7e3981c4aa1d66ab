#pragma once
// Classic fourth-order Runge-Kutta, in the lecture's form (digest section 6): state
// {x, v}, derivative {dx, dv} = {v, a}; each sample takes an Euler sub-step from the
// start with the previous sample's derivative:
//   k1 = f(t, y),  k2 = f(t + dt/2, y + dt/2 k1),  k3 = f(t + dt/2, y + dt/2 k2),
//   k4 = f(t + dt, y + dt k3),  y += dt (k1 + 2 (k2 + k3) + k4) / 6.
#include "core/concepts.hpp"

namespace stepbench {

struct rk4 {
  static constexpr std::string_view name = "rk4";
  static constexpr std::string_view description = "classic fourth-order Runge-Kutta";
  static constexpr int order = 4;

  template <class Sys, class Vec>
  void step(const Sys& sys, double t, step_state<Vec>& s, double dt) const {
    const double h = 0.5 * dt;
    // The dx of each sample is the velocity of the previous sub-step.
    const Vec& dv1 = current_acceleration(sys, t, s);
    const Vec x2 = s.x + h * s.v, v2 = s.v + h * dv1;
    const Vec dv2 = acceleration(sys, t + h, x2, v2);
    const Vec x3 = s.x + h * v2, v3 = s.v + h * dv2;
    const Vec dv3 = acceleration(sys, t + h, x3, v3);
    const Vec x4 = s.x + dt * v3, v4 = s.v + dt * dv3;
    const Vec dv4 = acceleration(sys, t + dt, x4, v4);
    s.x += (dt / 6.0) * (s.v + 2.0 * (v2 + v3) + v4);
    s.v += (dt / 6.0) * (dv1 + 2.0 * (dv2 + dv3) + dv4);
    s.a_current = false;
  }
};

}  // namespace stepbench

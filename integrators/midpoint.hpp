#pragma once
// Explicit midpoint rule (RK2): one Euler half step to the midpoint, then a full step
// with the midpoint's derivative.
//   x_m = x_n + dt/2 v_n,  v_m = v_n + dt/2 F(t_n, x_n, v_n) / m,
//   x_{n+1} = x_n + dt v_m,  v_{n+1} = v_n + dt F(t_n + dt/2, x_m, v_m) / m.
// Second order (Hairer, Norsett, Wanner I, sec. II.1).
#include "core/concepts.hpp"

namespace stepbench {

struct midpoint {
  static constexpr std::string_view name = "midpoint";
  static constexpr std::string_view description = "explicit midpoint (RK2)";
  static constexpr int order = 2;

  template <class Sys, class Vec>
  void step(const Sys& sys, double t, step_state<Vec>& s, double dt) const {
    const double h = 0.5 * dt, im = inverse_mass(sys);
    const Vec x_mid = s.x + h * s.v;
    const Vec v_mid = s.v + (h * im) * current_force(sys, t, s);
    s.v += (dt * im) * sys.force(t + h, x_mid, v_mid);
    s.x += dt * v_mid;
    s.f_current = false;
  }
};

}  // namespace stepbench

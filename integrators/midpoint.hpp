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
  static constexpr capabilities traits{};
  static constexpr int force_evals_per_step = 2;

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    Vec x_mid, v_mid, f_mid;
    explicit stepper(const midpoint&) {}
    void resize(const Sys&, const Vec& like) { size_like(like, x_mid, v_mid, f_mid); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double h = 0.5 * dt, im = inverse_mass(sys);
      x_mid = s.x + h * s.v;
      v_mid = s.v + (h * im) * current_force(sys, t, s);
      sys.force(t + h, x_mid, v_mid, f_mid);
      s.v += (dt * im) * f_mid;
      s.x += dt * v_mid;
      s.f_current = false;
    }
  };
};

}  // namespace stepbench

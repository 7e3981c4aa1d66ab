#pragma once
// Explicit (forward) Euler, as in the lecture's worked example: the position moves
// with the OLD velocity, then the velocity with the old acceleration.
//   x_{n+1} = x_n + dt v_n,   v_{n+1} = v_n + dt F(t_n, x_n, v_n) / m.
// First order; exact only when the rate of change is constant.
#include "core/concepts.hpp"

namespace stepbench {

struct euler {
  static constexpr std::string_view name = "euler";
  static constexpr std::string_view description = "explicit Euler: position with the old velocity";
  static constexpr int order = 1;
  static constexpr capabilities traits{};
  static constexpr int force_evals_per_step = 1;

  template <class Sys, class Vec>
  void step(const Sys& sys, double t, step_state<Vec>& s, double dt) const {
    const Vec& f = current_force(sys, t, s);
    s.x += dt * s.v;
    s.v += (dt * inverse_mass(sys)) * f;
    s.f_current = false;
  }
};

}  // namespace stepbench

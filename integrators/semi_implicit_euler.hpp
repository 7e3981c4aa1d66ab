#pragma once
// Semi-implicit (symplectic) Euler: velocity first, then position with the NEW velocity.
//   v_{n+1} = v_n + dt F(t_n, x_n, v_n) / m,   x_{n+1} = x_n + dt v_{n+1}.
// First order, but symplectic for separable forces (Hairer, Lubich, Wanner, "Geometric
// Numerical Integration", Thm. VI.3.3): its energy error stays bounded on oscillators.
#include "core/concepts.hpp"

namespace stepbench {

struct semi_implicit_euler {
  static constexpr std::string_view name = "semi_implicit_euler";
  static constexpr std::string_view description = "semi-implicit Euler: velocity first, then position";
  static constexpr int order = 1;
  static constexpr capabilities traits{.symplectic = true};
  static constexpr int force_evals_per_step = 1;

  template <class Sys, class Vec>
  void step(const Sys& sys, double t, step_state<Vec>& s, double dt) const {
    s.v += (dt * inverse_mass(sys)) * current_force(sys, t, s);
    s.x += dt * s.v;
    s.f_current = false;
  }
};

}  // namespace stepbench

#pragma once
// The lecture's momentum form (integration): integrate the force into momentum,
// derive the velocity, then move.
//   p_{n+1} = p_n + dt F(t_n, x_n, v_n),   v_{n+1} = p_{n+1} / m,   x_{n+1} = x_n + dt v_{n+1}.
// With p = m v this is semi-implicit Euler up to rounding (first order, symplectic); it
// is kept as its own method because it is the form that carries over to rotation
// (angular momentum, inertia tensor), where p, not v, is the natural state.
#include "core/concepts.hpp"

namespace stepbench {

struct momentum {
  static constexpr std::string_view name = "momentum";
  static constexpr std::string_view description = "momentum form: p += F dt, v = p / m, x += v dt";
  static constexpr int order = 1;
  static constexpr capabilities traits{.symplectic = true};
  static constexpr int force_evals_per_step = 1;

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    Vec p;
    explicit stepper(const momentum&) {}
    void resize(const Sys&, const Vec& like) { size_like(like, p); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double m = sys.mass();
      p = m * s.v + dt * current_force(sys, t, s);
      s.v = p / m;
      s.x += dt * s.v;
      s.f_current = false;
    }
  };
};

}  // namespace stepbench

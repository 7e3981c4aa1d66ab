#pragma once
// Implicit (backward) Euler, one of the improvements the lecture recommends
// (integration): the new state is defined by the forces at the END of the step,
//   x_{n+1} = x_n + dt v_{n+1},   v_{n+1} = v_n + dt F(t_{n+1}, x_{n+1}, v_{n+1}) / m,
// solved by Newton's method (integrators/implicit_newton.hpp). First order and
// L-stable (Hairer & Wanner, Solving ODEs II, sec. IV.3): stable for every dt on every
// decaying or oscillating linear mode, at the price of numerical damping that removes
// energy from an undamped oscillator.
#include <stdexcept>
#include <string>

#include "core/concepts.hpp"
#include "integrators/implicit_newton.hpp"

namespace stepbench {

struct implicit_euler {
  static constexpr std::string_view name = "implicit_euler";
  static constexpr std::string_view description = "implicit (backward) Euler, Newton iterations";
  static constexpr int order = 1;
  static constexpr capabilities traits{.needs_jacobian = true};

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    backward_euler_newton<Sys> newton;
    explicit stepper(const implicit_euler&) {}
    void resize(const Sys& sys, const Vec& like) { newton.resize(sys, like); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      // Predictor: the velocity at the start of the step. With set-valued friction, the
      // step ends at rest where v_{n+1} = 0.
      if (!newton.solve_stage(sys, t + dt, dt, s.x, s.v, 0.0))
        throw std::runtime_error("implicit_euler: Newton found no root for the step to t = " + std::to_string(t + dt));
      s.x = newton.x1;
      s.v = newton.v1;
      s.f = newton.f;  // F(t + dt, x_{n+1}, v_{n+1}): the next step's F_n
      // With friction resolved by projection, f holds the friction the step applied, not
      // the problem's force law at the new state.
      s.f_current = !has_set_valued_friction<Sys>;
    }
  };
};

}  // namespace stepbench

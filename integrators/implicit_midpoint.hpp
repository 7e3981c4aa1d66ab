#pragma once
// The implicit midpoint rule: the step uses the force at the average of the old and
// the new state,
//   x_{n+1} = x_n + dt (v_n + v_{n+1}) / 2,
//   v_{n+1} = v_n + dt F(t_n + dt/2, (x_n + x_{n+1}) / 2, (v_n + v_{n+1}) / 2) / m.
// Second order, symplectic (Hairer, Lubich & Wanner, Geometric Numerical Integration,
// Thm. VI.3.5) and A-stable: it neither gains nor loses energy on an undamped linear
// oscillator at any dt (|R(iy)| = 1), where implicit Euler damps it.
// With the midpoint state (x_m, v_m) as unknown, x_m = x_n + (dt/2) v_m and
// m (v_m - v_n) = (dt/2) F(t_n + dt/2, x_m, v_m): a backward-Euler step of dt/2 to the
// midpoint (the same Newton solve as implicit_euler), then x_{n+1} = x_n + dt v_m and
// v_{n+1} = 2 v_m - v_n (Hairer, Lubich & Wanner, sec. II.1, the midpoint rule as the
// composition of implicit and explicit Euler half steps).
#include <stdexcept>
#include <string>

#include "core/concepts.hpp"
#include "integrators/implicit_newton.hpp"

namespace stepbench {

struct implicit_midpoint {
  static constexpr std::string_view name = "implicit_midpoint";
  static constexpr std::string_view description = "implicit midpoint rule (symplectic, A-stable), Newton iterations";
  static constexpr int order = 2;
  static constexpr capabilities traits{.symplectic = true, .needs_jacobian = true};

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    backward_euler_newton<Sys> newton;
    explicit stepper(const implicit_midpoint&) {}
    void resize(const Sys& sys, const Vec& like) { newton.resize(sys, like); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double h = 0.5 * dt;
      // With set-valued friction, the step ends at rest where v_{n+1} = 2 v_m - v_n = 0.
      if (!newton.solve_stage(sys, t + h, h, s.x, s.v, 0.5))
        throw std::runtime_error("implicit_midpoint: Newton found no root for the step to t = " +
                                 std::to_string(t + dt));
      s.x += dt * newton.v1;
      s.v = 2.0 * newton.v1 - s.v;
      s.f_current = false;
    }
  };
};

}  // namespace stepbench

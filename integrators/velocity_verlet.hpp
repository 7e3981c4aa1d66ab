#pragma once
// Velocity Verlet (Swope et al., J. Chem. Phys. 76, 637 (1982)):
//   v_h = v_n + dt/2 a_n,  x_{n+1} = x_n + dt v_h,  v_{n+1} = v_h + dt/2 a_{n+1}.
// Second order and symplectic for forces that depend on position only; then F_{n+1}
// is exactly the next step's F_n, so it is cached and the method costs one force
// evaluation per step.
//
// A velocity-dependent force (a damper) needs v_{n+1} to compute a_{n+1}. We evaluate
// it at the predicted velocity v_n + dt a_n (an Euler predictor), which makes the
// velocity update Heun's trapezoidal rule and keeps the method second order; the
// cached force is then not the one at the true v_{n+1}, so it is recomputed (two
// evaluations per step).
#include "core/concepts.hpp"

namespace stepbench {

struct velocity_verlet {
  static constexpr std::string_view name = "velocity_verlet";
  static constexpr std::string_view description = "velocity Verlet (Stormer-Verlet, kick-drift-kick)";
  static constexpr int order = 2;
  static constexpr capabilities traits{.symplectic = true, .reuses_last_force = true};

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    Vec f_n, v_half, v_pred, f_new;
    explicit stepper(const velocity_verlet&) {}
    void resize(const Sys&, const Vec& like) { size_like(like, f_n, v_half, v_pred, f_new); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double h_im = 0.5 * dt * inverse_mass(sys);
      f_n = current_force(sys, t, s);
      v_half = s.v + h_im * f_n;
      s.x += dt * v_half;
      if constexpr (Sys::force_depends_on_velocity) {
        v_pred = v_half + h_im * f_n;
        sys.force(t + dt, s.x, v_pred, f_new);
        s.v = v_half + h_im * f_new;
        s.f_current = false;
      } else {
        sys.force(t + dt, s.x, v_half, s.f);
        s.v = v_half + h_im * s.f;
        s.f_current = true;
      }
    }
  };
};

}  // namespace stepbench

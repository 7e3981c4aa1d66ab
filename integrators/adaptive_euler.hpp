#pragma once
// Adaptive Euler, the first of the improvements the lecture recommends (integration):
// explicit Euler with its step size chosen to meet a tolerance. The error of a step
// of h is estimated by step doubling (HNW I, sec. II.4): one step of h and two of h/2;
// their difference estimates the local error of the two half steps, which are the state
// kept (the h^2 error terms are C h^2 for the full step and C h^2 / 2 for the halves, so
// the difference is the halves' error). The error is controlled per unit step (Shampine,
// Numerical Solution of ODEs, sec. 5.1; HNW I, sec. II.4): a step of h may make an
// error of tol h / T, so the errors of the T / h steps add up to about tol over the run
// and the global error follows the tolerance (controlling the error per step instead
// leaves a first-order method with a global error of about sqrt(tol)). Two force
// evaluations an attempt (the start's is shared by both paths and reused after a
// rejection). First order: the steps grow as 1 / tol, so tight tolerances are
// expensive, and the study's work budget skips those runs with the reason.
// Dense output: the cubic Hermite interpolant of the positions through the step's ends
// with their velocities (HNW I, sec. II.6), velocities its derivative; third order, more
// than the step's own, and free (no force evaluation).
#include "core/concepts.hpp"
#include "integrators/step_control.hpp"

namespace stepbench {

struct adaptive_euler {
  static constexpr std::string_view name = "adaptive_euler";
  static constexpr std::string_view description = "explicit Euler with step doubling and error control";
  static constexpr int order = 1;
  static constexpr capabilities traits{.error_estimate = true, .dense_output = true};
  static constexpr int force_evals_per_step = 2;
  double tol = 1e-6;
  explicit adaptive_euler(double tolerance) : tol(tolerance) {}

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    double tol;
    step_controller control{.error_order = 0};  // the error per unit step is O(h)
    double horizon = 1.0;
    Vec x_full, v_full, x_half, v_half, f_half, x1, v1, x0, v0;  // x0, v0: the last accepted step's start
    double h_last = 0.0;
    explicit stepper(const adaptive_euler& m) : tol(m.tol) {}
    void resize(const Sys&, const Vec& like) {
      size_like(like, x_full, v_full, x_half, v_half, f_half, x1, v1, x0, v0);
    }

    double initial_dt(const Sys& sys, double t, step_state<Vec>& s, double horizon) {
      this->horizon = horizon;
      return starting_step(sys, t, s, order, tol, horizon, x_half, v_half, f_half);
    }

    step_attempt try_step(const Sys& sys, double t, step_state<Vec>& s, double h) {
      const double im = inverse_mass(sys), hh = 0.5 * h;
      const Vec& f0 = current_force(sys, t, s);
      // One step of h.
      x_full = s.x + h * s.v;
      v_full = s.v + (h * im) * f0;
      // Two steps of h/2.
      x_half = s.x + hh * s.v;
      v_half = s.v + (hh * im) * f0;
      sys.force(t + hh, x_half, v_half, f_half);
      x1 = x_half + hh * v_half;
      v1 = v_half + (hh * im) * f_half;
      const double err = scaled_rms(x1 - x_full, v1 - v_full, s.x, s.v, x1, v1, tol) * (horizon / h);
      return control.attempt(h, err, [&] {
        x0 = s.x;
        v0 = s.v;
        h_last = h;
        s.x = x1;
        s.v = v1;
        s.f_current = false;
      });
    }

    // The state at theta h into the last accepted step; (x1, v1) still hold its end.
    void interpolate(double theta, Vec& x, Vec& v) const {
      const double t2 = theta * theta, t3 = t2 * theta;
      const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + theta, h01 = 3 * t2 - 2 * t3, h11 = t3 - t2;
      const double d00 = 6 * t2 - 6 * theta, d10 = 3 * t2 - 4 * theta + 1, d11 = 3 * t2 - 2 * theta;
      x = h00 * x0 + (h10 * h_last) * v0 + h01 * x1 + (h11 * h_last) * v1;
      v = (d00 / h_last) * (x0 - x1) + d10 * v0 + d11 * v1;
    }
  };
};

}  // namespace stepbench

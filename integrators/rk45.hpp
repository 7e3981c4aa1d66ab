#pragma once
// Dormand-Prince 5(4) (Dormand & Prince, J. Comp. Appl. Math. 6 (1980) 19; the DOPRI5
// of HNW I, sec. II.5), adaptive: 7 stages, first same as last (6 force evaluations a
// step), the fifth-order solution kept and the embedded fourth-order one used for the
// error estimate; the PI step-size controller of dopri5.f (beta = 0.04; HNW I sec. IV.2,
// integrators/step_control.hpp); and Shampine's quartic dense output, so that the
// sample times are interpolated inside the steps instead of shortening them. The
// coefficients are integrators/tableaus.hpp's, proved in tests/test_tableaus.cpp; the
// stages are integrators/unrolled_rk.hpp's in the velocity form, whatever the force.
#include "core/concepts.hpp"
#include "integrators/step_control.hpp"
#include "integrators/tableaus.hpp"
#include "integrators/unrolled_rk.hpp"

namespace stepbench {

struct rk45 {
  static constexpr std::string_view name = "rk45";
  static constexpr std::string_view description = "Dormand-Prince 5(4), PI step control, dense output";
  static constexpr int order = 5;
  static constexpr capabilities traits{.reuses_last_force = true, .error_estimate = true, .dense_output = true};
  static constexpr int force_evals_per_step = 6;
  // b - b_hat: the weights of the embedded error estimate.
  static constexpr std::array<double, 7> error_weights = [] {
    std::array<double, 7> e{};
    for (int i = 0; i < 7; ++i) e[i] = dopri5_tableau.b[i] - dopri5_tableau.b_hat[i];
    return e;
  }();
  double tol = 1e-6;
  explicit rk45(double tolerance) : tol(tolerance) {}

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    double tol;
    step_controller control{.error_order = 4, .beta = 0.04};
    unrolled_rk<dopri5_tableau, Sys, false> k;
    Vec ex, ev, x0, v0;  // error estimate; start of the last accepted step (dense output)
    double h_last = 0.0, h_im_last = 0.0;
    explicit stepper(const rk45& m) : tol(m.tol) {}
    void resize(const Sys&, const Vec& like) {
      k.resize(like);
      size_like(like, ex, ev, x0, v0);
    }

    double initial_dt(const Sys& sys, double t, step_state<Vec>& s, double horizon) {
      return starting_step(sys, t, s, order, tol, horizon, ex, ev, x0);
    }

    step_attempt try_step(const Sys& sys, double t, step_state<Vec>& s, double h) {
      const double h_im = h * inverse_mass(sys);
      k.F[0] = current_force(sys, t, s);
      k.template compute<1, 7>(sys, t, s.x, s.v, h, h_im);
      // The last stage is f(t + h, y1): y1 = (k.X, k.V[6]), its force k.F[6].
      k.template difference<error_weights>(ex, ev, s.v, h, h_im);
      const double err = scaled_rms(ex, ev, s.x, s.v, k.X, k.V[6], tol);
      return control.attempt(h, err, [&] {
        x0 = s.x;
        v0 = s.v;
        h_last = h;
        h_im_last = h_im;
        s.x = k.X;
        s.v = k.V[6];
        s.f = k.F[6];
        s.f_current = true;
      });
    }

    // The state at t_n + theta h of the last accepted step (0 <= theta <= 1).
    void interpolate(double theta, Vec& x, Vec& v) const {
      k.combine(dopri5_dense_weights(theta), h_last, h_im_last, x0, v0, x, v);
    }
  };
};

}  // namespace stepbench

#pragma once
// Eighth-order explicit Runge-Kutta at a fixed step: the step of DOP853 (Dormand &
// Prince; Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., sec. II.6 and dop853.f),
// its 12 stages and eighth-order weights b, without the error estimate. 12 force
// evaluations a step: f(t + h, y_1), DOP853's 13th evaluation, is the next step's first
// stage. Coefficients from integrators/tableaus.hpp (dop853_tableau), proved in
// tests/test_tableaus.cpp; the stages are integrators/unrolled_rk.hpp's (1/m folded,
// sums unrolled with the newest term last, the Nystrom form for a position-only force).
#include "core/concepts.hpp"
#include "integrators/tableaus.hpp"
#include "integrators/unrolled_rk.hpp"

namespace stepbench {

struct rk8 {
  static constexpr std::string_view name = "rk8";
  static constexpr std::string_view description = "eighth-order Runge-Kutta: the 12-stage DOP853 step at fixed dt";
  static constexpr int order = 8;
  static constexpr capabilities traits{};
  static constexpr int force_evals_per_step = 12;

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    unrolled_rk<dop853_tableau, Sys> k;
    explicit stepper(const rk8&) {}
    void resize(const Sys&, const Vec& like) { k.resize(like); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double h_im = dt * inverse_mass(sys);
      k.F[0] = current_force(sys, t, s);
      k.template compute<1, 12>(sys, t, s.x, s.v, dt, h_im);
      k.template combine<dop853_tableau.b>(s.x, s.v, s.x, s.v, dt, h_im);
      s.f_current = false;
    }
  };
};

}  // namespace stepbench

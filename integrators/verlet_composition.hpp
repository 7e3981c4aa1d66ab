#pragma once
// A symmetric composition of velocity Verlet, stepped as its kick-drift sequence
// (integrators/tableau.hpp's kick_drift_sequence, the coefficients in
// integrators/tableaus.hpp): for i = 0..N-1
//   v += kick[i] h F(x) / m,   x += drift[i] h v,   then   v += kick[N] h F(x) / m.
// The method is the data: forest_ruth is this stepper over triple_jump4_kick_drift, and
// a higher-order one would be the same over kick_drift of its composition (tableaus.hpp).
//
// Position-only force: N force evaluations a step. Adjacent kicks of two sub-steps act
// at the same x and are merged in the sequence; the last kick's force, at the step's new
// x, is the next step's first (cached in the state, as velocity Verlet does). Symplectic,
// and of the composition's order (Yoshida, Phys. Lett. A 150 (1990) 262; Hairer, Lubich
// & Wanner, Geometric Numerical Integration, 2nd ed., sec. II.4, II.5).
//
// Velocity-dependent force (a damper, drag): a kick is then the flow of v' = F(x, v) / m
// at fixed x, which one force evaluation no longer gives. Each kick is taken as one
// classic RK4 step of that flow (4 evaluations): exact to O(tau^5), so the composition
// differs from the one with exact kicks (a symmetric method, of the composition's order
// up to 4) by O(h^5) a step, and keeps order 4 (not beyond: an order-8 set would need
// more accurate kicks). 4 (N + 1) evaluations a step; no longer symplectic (nothing with
// a damper is).

#include "core/concepts.hpp"
#include "integrators/tableau.hpp"

namespace stepbench {

template <const auto& Seq, class Sys>
struct composition_stepper {
  using Vec = typename Sys::vec;
  static constexpr int substeps = static_cast<int>(std::tuple_size_v<decltype(Seq.drift)>);
  Vec k1, k2, k3, k4, v_stage;

  void resize(const Sys&, const Vec& like) { size_like(like, k1, k2, k3, k4, v_stage); }

  void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
    const double h_im = dt * inverse_mass(sys);
    kick(sys, t, s, Seq.kick[0] * dt, Seq.kick[0] * h_im);
    double tau = t;
    for (int i = 0; i < substeps; ++i) {
      s.x += (Seq.drift[i] * dt) * s.v;
      s.f_current = false;
      tau += Seq.drift[i] * dt;
      kick(sys, tau, s, Seq.kick[i + 1] * dt, Seq.kick[i + 1] * h_im);
    }
    // A position-only force's last F, at the new x, is the next step's first kick.
    s.f_current = !Sys::force_depends_on_velocity;
  }

 private:
  // v' = F(t, x, v) / m at fixed x over tau (c = tau / m): v += c F(x) for a position-only
  // force (F cached in the state), else by one classic RK4 step.
  void kick(const Sys& sys, double t, step_state<Vec>& s, double tau, double c) {
    if constexpr (!Sys::force_depends_on_velocity) {
      s.v += c * current_force(sys, t, s);
    } else {
      sys.force(t, s.x, s.v, k1);
      v_stage = s.v + (0.5 * c) * k1;
      sys.force(t + 0.5 * tau, s.x, v_stage, k2);
      v_stage = s.v + (0.5 * c) * k2;
      sys.force(t + 0.5 * tau, s.x, v_stage, k3);
      v_stage = s.v + c * k3;
      sys.force(t + tau, s.x, v_stage, k4);
      s.v += (c / 6.0) * (k1 + 2.0 * (k2 + k3) + k4);
    }
  }
};

}  // namespace stepbench

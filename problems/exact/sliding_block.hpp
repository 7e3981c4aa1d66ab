#pragma once
// Exact motion of a block on an incline with Coulomb friction, the lecture's friction
// (among its forces): normal force |F_n| = m g cos(theta), friction mu |F_n| against
// the motion, kinetic mu_k while sliding, static mu_s (up to mu_s |F_n|) at rest.
//
// Coordinate s along the slope, positive UP the slope, s(0) = 0, initial velocity v0 (the
// brief's case is v0 > 0: pushed up the slope). Gravity's component along the slope is
// -g sin(theta); kinetic friction is -sign(v) mu_k g cos(theta). Hence, piecewise:
//
// Phase 1 (0 <= t <= t1), sliding with the initial direction of motion:
//   v0 > 0 (moving up):   a1 = -g (sin theta + mu_k cos theta) < 0, always stops, at
//                         t1 = v0 / |a1|, after s1 = v0 t1 / 2 = v0^2 / (2 |a1|).
//   v0 < 0 (moving down): a1 = -g (sin theta - mu_k cos theta), i.e. the lecture's "a = g sin -
//                         mu_k g cos" down the slope. It stops (at t1 = v0 / a1) only if
//                         kinetic friction wins, mu_k > tan theta; otherwise t1 = +inf.
//   v0 = 0:               no phase 1, t1 = 0.
//   s = t (v0 + a1 t / 2), v = v0 + a1 t.
// Phase 2 (t > t1), starting at rest at s1:
//   Static friction can hold the block iff m g sin theta <= mu_s m g cos theta, i.e.
//   tan theta <= mu_s (the lecture's slip angle theta = atan(mu_s)). If it holds, the block
//   stays at rest forever. Otherwise it slides down with a2 = -g (sin theta - mu_k cos theta),
//   s = s1 + a2 (t - t1)^2 / 2, v = a2 (t - t1).
//   The case mu_s < tan theta <= mu_k (kinetic above static, as in the lecture table's
//   aluminum on aluminum) is where the Coulomb model is not self-consistent: static friction
//   cannot hold the block, but as soon as it moved, kinetic friction (mu_k m g cos theta >=
//   m g sin theta) would decelerate it back to rest, so no motion away from rest exists. The
//   only consistent solution is rest; this code returns it. So the block stays at rest iff
//   tan theta <= max(mu_s, mu_k) (computed as sin theta <= mu cos theta, safe at 90 degrees).
//
// Numerics: s = t (v0 + a1 t / 2) has no cancellation on [0, t1] (the bracket stays >= v0 / 2).
// v is v0 + a1 t on the first half of phase 1 (exactly v0 at t = 0) and a1 (t - t1) on the
// second (exactly 0 at t1, no cancellation of v0 against a1 t). sin theta - mu_k cos theta
// cancels when tan theta is near mu_k; that is the problem's own conditioning with respect to
// theta and mu_k (relative error ~ eps tan theta / |tan theta - mu_k|), not the formula's.
#include <algorithm>
#include <cmath>
#include <limits>

namespace stepbench::exact {

// Position up the slope, velocity up the slope, acceleration up the slope.
struct slide_state {
  double s, v, a;
};

struct sliding_block {
  double g = 9.8;
  double theta = 0.5235987755982988;  // incline angle [rad], 0 <= theta <= pi/2 (default 30 deg)
  double mu_s = 0.5;                  // static friction coefficient
  double mu_k = 0.5;                  // kinetic friction coefficient
  double v0 = 1.0;                    // initial velocity along the slope, positive up

  // Magnitude of the deceleration while moving up: g (sin theta + mu_k cos theta).
  double up_deceleration() const { return g * (std::sin(theta) + mu_k * std::cos(theta)); }
  // Acceleration down the slope while moving down: g (sin theta - mu_k cos theta) (the
  // lecture's worked example; negative when kinetic friction wins).
  double down_acceleration() const { return g * (std::sin(theta) - mu_k * std::cos(theta)); }
  // True when the block, once at rest, stays at rest: tan theta <= max(mu_s, mu_k) (see above).
  bool stays_at_rest() const { return std::sin(theta) <= std::max(mu_s, mu_k) * std::cos(theta); }

  // Acceleration (up the slope) during phase 1.
  double phase1_acceleration() const {
    if (v0 > 0.0) return -up_deceleration();
    if (v0 < 0.0) return -down_acceleration();
    return 0.0;
  }
  // End of phase 1: when the block first comes to rest (+inf if it never does).
  double stop_time() const {
    if (v0 == 0.0) return 0.0;
    const double a1 = phase1_acceleration();
    if (v0 * a1 >= 0.0) return std::numeric_limits<double>::infinity();  // not decelerating
    return -v0 / a1;
  }
  // Where it comes to rest: s1 = v0 t1 / 2 (as v0 + a1 t1 = 0).
  double stop_position() const { return 0.5 * v0 * stop_time(); }
  // Acceleration (up the slope) during phase 2: 0 when static friction holds.
  double phase2_acceleration() const { return stays_at_rest() ? 0.0 : -down_acceleration(); }

  slide_state at(double t) const {
    if (!(t > 0.0)) return {0.0, v0, v0 == 0.0 ? phase2_acceleration() : phase1_acceleration()};
    const double t1 = stop_time();
    if (t <= t1) {
      const double a1 = phase1_acceleration();
      const double v = t <= 0.5 * t1 ? v0 + a1 * t : a1 * (t - t1);
      return {t * (v0 + 0.5 * a1 * t), v, a1};
    }
    const double a2 = phase2_acceleration(), tau = t - t1;
    return {stop_position() + 0.5 * a2 * tau * tau, a2 * tau, a2};
  }
};

}  // namespace stepbench::exact

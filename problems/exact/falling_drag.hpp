#pragma once
// Exact fall from rest under gravity with quadratic air drag F_d = -c |v| v. (The lecture's
// forces are gravity, the normal force, friction and springs; it has no air drag. This is
// the standard quadratic model, a drag proportional to v^2 as at game speeds in air.) Measured
// downward (x = distance fallen, v = downward speed), the body obeys
//   m dv/dt = m g - c v^2,   v(0) = 0, x(0) = 0,
// i.e. dv/dt = g (1 - (v / v_t)^2) with the terminal speed v_t = sqrt(m g / c). Separating
// variables (integral of dv / (1 - v^2/v_t^2) = v_t artanh(v / v_t)) gives, with u = g t / v_t,
//   v = v_t tanh(u),   x = integral of v dt = (v_t^2 / g) ln cosh(u),
//   a = dv/dt = g (1 - tanh^2 u) = g / cosh^2(u).
// (E.g. Taylor, "Classical Mechanics", sec. 2.4.) Valid for t >= 0 only: for t < 0 the body
// would move up, the drag would point down, and the ODE would change; before release the body
// is taken as held at rest.
//
// Written without overflow for large t and without cancellation for small t:
// - ln cosh u = 0.5 log1p(sinh^2 u) for u < 20 (relatively accurate down to u -> 0, where it
//   is u^2 / 2), and u - ln 2 + log1p(e^{-2u}) from u = 20 on (no overflow; there u dominates).
// - x = (v_t t) (ln cosh(u) / u): tends to v_t t - (v_t^2 / g) ln 2 for large t without
//   forming v_t^2 (which overflows for v_t > 1e154).
// - a = 4 g w / (1 + w)^2 with w = e^{-2u}: no cosh overflow, no 1 - tanh^2 cancellation.
// - For u < 1e-4 the Taylor series tanh u = u (1 - u^2/3 + 2u^4/15 - ...), ln cosh u =
//   (u^2/2)(1 - u^2/6 + 2u^4/45 - ...): v = g t (1 - u^2/3), x = (g t^2 / 2)(1 - u^2/6); the
//   terms left out are below 1.4e-17 relative. This branch also covers v_t = +inf (no drag,
//   u = 0: free fall v = g t, x = g t^2 / 2 exactly) and u so small that u^2 would underflow
//   (where v_t tanh(u) and (v_t^2 / g) ln cosh(u) would give 0 * inf or lose x to underflow).
#include <cmath>
#include <numbers>

namespace stepbench::exact {

// ln cosh(u), relatively accurate for every finite u (even function).
inline double log_cosh(double u) {
  const double a = std::abs(u);
  if (a < 20.0) {
    const double s = std::sinh(a);
    return 0.5 * std::log1p(s * s);
  }
  return (a - std::numbers::ln2) + std::log1p(std::exp(-2.0 * a));
}

// Distance fallen, downward speed and downward acceleration.
struct fall_state {
  double x, v, a;
};

struct falling_drag {
  double g = 9.8;                // gravitational acceleration
  double terminal_speed = 50.0;  // v_t = sqrt(m g / c); +inf for no drag

  // From the mass and the drag coefficient c of F_d = -c |v| v (c = 0 gives v_t = +inf).
  static falling_drag from_mass_and_drag(double g, double mass, double c) { return {g, std::sqrt(mass * g / c)}; }

  fall_state at(double t) const {
    if (!(t > 0.0)) return {0.0, 0.0, 0.0};
    const double vt = terminal_speed;
    const double u = g * t / vt;
    const double w = std::exp(-2.0 * u);
    const double a = 4.0 * g * w / ((1.0 + w) * (1.0 + w));
    if (u < 1e-4) {
      const double u2 = u * u;
      return {0.5 * g * t * t * (1.0 - u2 / 6.0), g * t * (1.0 - u2 / 3.0), a};
    }
    return {vt * t * (log_cosh(u) / u), vt * std::tanh(u), a};
  }
};

}  // namespace stepbench::exact

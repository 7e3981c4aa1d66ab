#pragma once
// A body falling from rest under gravity with quadratic air drag F_d = -c |v| v (the
// standard model at game speeds in air; the lecture's forces have none).
// Measured downward (x the distance fallen, v the downward speed):
//   m dv/dt = m g - c |v| v,   terminal speed v_t = sqrt(m g / c),
// closed form v = v_t tanh(g t / v_t), x = (v_t^2 / g) ln cosh(g t / v_t)
// (problems/exact/falling_drag.hpp). With c = 0 it is the lecture's free fall,
// x = g t^2 / 2. Defaults: a 1 kg body with c = 0.0245 kg/m, so v_t = 20 m/s, reached
// (to 1 %) after 2.7 s; the horizon, 5 s, covers the approach to it. The drag
// dissipates energy, so the energy error is taken against the closed form's energy.
#include <Eigen/Core>
#include <cmath>

#include "core/concepts.hpp"
#include "problems/exact/falling_drag.hpp"

namespace stepbench {

struct falling_drag {
  static constexpr std::string_view name = "falling_drag";
  static constexpr std::string_view description = "fall from rest with quadratic air drag, v_t = 20 m/s (x downward)";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = true;
  static constexpr int dim() { return 1; }
  using vec = Eigen::Matrix<double, 1, 1>;
  using jacobian_matrix = Eigen::Matrix<double, 1, 1>;

  double mass_kg = 1.0;
  double gravity = 9.8;
  double drag = 0.0245;
  double duration = 5.0;

  static constexpr auto parameters() {
    using p = param<falling_drag>;
    return std::array{
        p{"mass_kg", &falling_drag::mass_kg, "kg", "mass", positive},
        p{"gravity", &falling_drag::gravity, "m/s^2", "gravitational acceleration", positive},
        p{"drag", &falling_drag::drag, "kg/m", "drag coefficient c of F = -c |v| v (0: free fall)", non_negative},
        p{"duration", &falling_drag::duration, "s", "default horizon", positive},
    };
  }

  exact::falling_drag motion() const { return exact::falling_drag::from_mass_and_drag(gravity, mass_kg, drag); }

  double mass() const { return mass_kg; }
  double horizon() const { return duration; }
  void force(double, const vec&, const vec& v, vec& f) const {
    f[0] = mass_kg * gravity - drag * std::abs(v[0]) * v[0];
  }
  // dF/dx = 0, dF/dv = -2 c |v|.
  jacobian_matrix make_jacobian() const { return jacobian_matrix::Zero(); }
  void jacobian(double, const vec&, const vec& v, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx(0, 0) = 0.0;
    dfdv(0, 0) = -2.0 * drag * std::abs(v[0]);
  }
  phase<vec> initial() const { return {vec(0.0), vec(0.0)}; }
  phase<vec> exact(double t) const {
    const auto s = motion().at(t);
    return {vec(s.x), vec(s.v)};
  }
  // Kinetic plus potential energy, the height being -x.
  double energy(const vec& x, const vec& v) const { return 0.5 * mass_kg * v.squaredNorm() - mass_kg * gravity * x[0]; }
};

}  // namespace stepbench

#pragma once
// Projectile motion (the lecture's): up is +z, gravity g = [0, 0, -g]. Launched from
// the origin along +x at `speed` and `angle_deg` above the horizon. The horizon is the
// flight time back to launch height, 2 v_z / g. Closed form x(t) = x0 + v0 t + g t^2 / 2.
#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "core/concepts.hpp"

namespace stepbench {

struct projectile {
  static constexpr std::string_view name = "projectile";
  static constexpr std::string_view description = "3-D ball under uniform gravity, launched from the ground";
  static constexpr int dim() { return 3; }
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = false;
  using vec = Eigen::Vector3d;

  double speed = 50.0;
  double angle_deg = 70.0;
  double gravity = 9.8;
  double mass_kg = 1.0;

  static constexpr auto parameters() {
    using p = param<projectile>;
    return std::array{
        p{"speed", &projectile::speed, "m/s", "launch speed", positive},
        p{"angle_deg", &projectile::angle_deg, "deg", "elevation above +x (so the ball flies)", in_open(0.0, 180.0)},
        p{"gravity", &projectile::gravity, "m/s^2", "magnitude of g, along -z", positive},
        p{"mass_kg", &projectile::mass_kg, "kg", "mass", positive},
    };
  }

  double angle_rad() const { return angle_deg * std::numbers::pi / 180.0; }
  vec launch_velocity() const { return {speed * std::cos(angle_rad()), 0.0, speed * std::sin(angle_rad())}; }
  vec g() const { return {0.0, 0.0, -gravity}; }

  double mass() const { return mass_kg; }
  void force(double, const vec&, const vec&, vec& f) const { f = mass_kg * g(); }
  phase<vec> initial() const { return {vec::Zero(), launch_velocity()}; }
  double horizon() const { return flight_time(); }

  phase<vec> exact(double t) const {
    const vec v0 = launch_velocity();
    return {v0 * t + 0.5 * g() * t * t, v0 + g() * t};
  }
  double energy(const vec& x, const vec& v) const {
    return 0.5 * mass_kg * v.squaredNorm() + mass_kg * gravity * x.z();
  }

  // The lecture's flight time, launch and landing at the same height.
  double flight_time() const { return 2.0 * launch_velocity().z() / gravity; }
};

}  // namespace stepbench

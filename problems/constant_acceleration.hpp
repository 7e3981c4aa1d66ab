#pragma once
// The lecture's Euler worked example (integration): a constant force of 10 N on a 1 kg
// body from rest for 10 s. Closed form x(t) = x0 + v0 t + (F/m) t^2 / 2; the exact
// distance is 500 m. Explicit Euler with dt = 1 s gives 450 m (the lecture's 470 m is
// wrong), semi-implicit Euler 550 m.
#include <Eigen/Core>

#include "core/concepts.hpp"

namespace stepbench {

struct constant_acceleration {
  static constexpr std::string_view name = "constant_acceleration";
  static constexpr std::string_view description = "1-D body under a constant force (lecture's Euler example)";
  static constexpr int dim() { return 1; }
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = false;
  using vec = Eigen::Matrix<double, 1, 1>;

  double force_n = 10.0;
  double mass_kg = 1.0;
  double x0 = 0.0;
  double v0 = 0.0;
  double duration = 10.0;

  static constexpr auto parameters() {
    using p = param<constant_acceleration>;
    return std::array{
        p{"force_n", &constant_acceleration::force_n, "N", "constant applied force"},
        p{"mass_kg", &constant_acceleration::mass_kg, "kg", "mass", positive},
        p{"x0", &constant_acceleration::x0, "m", "initial position"},
        p{"v0", &constant_acceleration::v0, "m/s", "initial velocity"},
        p{"duration", &constant_acceleration::duration, "s", "default horizon", positive},
    };
  }

  double mass() const { return mass_kg; }
  void force(double, const vec&, const vec&, vec& f) const { f[0] = force_n; }
  phase<vec> initial() const { return {vec(x0), vec(v0)}; }
  double horizon() const { return duration; }

  phase<vec> exact(double t) const {
    const double a = force_n / mass_kg;
    return {vec(x0 + v0 * t + 0.5 * a * t * t), vec(v0 + a * t)};
  }
  // Kinetic plus the potential of the constant force, U = -F x: conserved exactly.
  double energy(const vec& x, const vec& v) const { return 0.5 * mass_kg * v.squaredNorm() - force_n * x[0]; }
};

}  // namespace stepbench

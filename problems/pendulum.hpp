#pragma once
// Simple pendulum (the lecture's example programs: the console pendulum):
// theta'' = -(g/L) sin(theta), released from rest at theta0.
//
// State is the angle: x = theta [rad], v = theta' [rad/s]. The integrators see the
// torque as the force, F = -m g L sin(theta), and the moment of inertia m L^2 as the
// mass, so F / m is the angular acceleration.
//
// Closed form (e.g. Lawden, "Elliptic Functions and Applications", sec. 5.2): with
// k = sin(theta0 / 2), w0 = sqrt(g / L) and K = K(k) the complete elliptic integral of
// the first kind,
//   sin(theta / 2) = k sn(K - w0 t | k^2),   theta' = -2 k w0 cn(K - w0 t | k^2),
// (differentiate: cos(theta/2) = dn, and d sn/du = cn dn). The exact period is
// T = 4 K(k) / w0. sn, cn come from gsl_sf_elljac_e, K from the AGM (below).
#include <gsl/gsl_sf_elljac.h>

#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "core/concepts.hpp"
#include "core/constraints.hpp"

namespace stepbench {

struct pendulum {
  static constexpr std::string_view name = "pendulum";
  static constexpr std::string_view description = "simple pendulum, large swing, released from rest";
  static constexpr int dim() { return 1; }
  static constexpr std::string_view position_unit = "rad";
  static constexpr bool force_depends_on_velocity = false;
  using vec = Eigen::Matrix<double, 1, 1>;

  double gravity = 9.8;
  double length_m = 1.0;
  double mass_kg = 1.0;
  double theta0_deg = 120.0;
  double periods = 2.0;

  static constexpr auto parameters() {
    using p = param<pendulum>;
    return std::array{
        p{"gravity", &pendulum::gravity, "m/s^2", "gravitational acceleration", positive},
        p{"length_m", &pendulum::length_m, "m", "rod length", positive},
        p{"mass_kg", &pendulum::mass_kg, "kg", "bob mass", positive},
        p{"theta0_deg", &pendulum::theta0_deg, "deg", "release angle from the bottom", in_open(0.0, 180.0)},
        p{"periods", &pendulum::periods, "1", "default horizon in exact periods", positive},
    };
  }

  double theta0() const { return theta0_deg * std::numbers::pi / 180.0; }
  double omega0() const { return std::sqrt(gravity / length_m); }
  double modulus() const { return std::sin(0.5 * theta0()); }
  // K(k) = pi / (2 AGM(1, k')) with the complementary modulus k' = cos(theta0 / 2)
  // (Abramowitz & Stegun 17.6.1). Taking k' directly keeps its digits as theta0 -> 180
  // deg, where k = sin(theta0 / 2) -> 1 and anything computed from 1 - k^2 cancels
  // (gsl_sf_ellint_Kcomp(k) loses ~1e-6 of the period at 179.9999 deg). The AGM
  // converges quadratically: 5 rounds at 120 deg, about 10 near 180.
  double quarter_period_k() const {
    // k' = cos(theta0 / 2) = sin((180 deg - theta0) / 2): the subtraction is exact near 180.
    double a = 1.0, b = std::sin((180.0 - theta0_deg) * (std::numbers::pi / 360.0));
    for (int i = 0; i < 64 && std::abs(a - b) > 1e-15 * a; ++i) {
      const double mean = 0.5 * (a + b);
      b = std::sqrt(a * b);
      a = mean;
    }
    return std::numbers::pi / (a + b);
  }
  double period() const { return 4.0 * quarter_period_k() / omega0(); }

  double mass() const { return mass_kg * length_m * length_m; }
  void force(double, const vec& x, const vec&, vec& f) const { f[0] = -mass_kg * gravity * length_m * std::sin(x[0]); }
  phase<vec> initial() const { return {vec(theta0()), vec(0.0)}; }
  double horizon() const { return periods * period(); }

  phase<vec> exact(double t) const {
    const double k = modulus();
    double sn, cn, dn;
    gsl_sf_elljac_e(quarter_period_k() - omega0() * t, k * k, &sn, &cn, &dn);
    return {vec(2.0 * std::asin(k * sn)), vec(-2.0 * k * omega0() * cn)};
  }
  double energy(const vec& x, const vec& v) const {
    return 0.5 * mass() * v.squaredNorm() + mass_kg * gravity * length_m * (1.0 - std::cos(x[0]));
  }

  // The constraint view: the bob a particle at L (sin theta, -cos theta) on a rigid link
  // to the pivot; back through theta = atan2(x, -y), theta' = (x y' - y x') / |p|^2.
  particle_system particles(const vec& x, const vec& v) const {
    particle_system s;
    s.x = Eigen::Vector3d(length_m * std::sin(x[0]), -length_m * std::cos(x[0]), 0.0);
    s.v = Eigen::Vector3d(length_m * std::cos(x[0]) * v[0], length_m * std::sin(x[0]) * v[0], 0.0);
    s.inverse_mass = Eigen::VectorXd::Constant(1, 1.0 / mass_kg);
    s.acceleration = {0.0, -gravity, 0.0};
    s.constraints.push_back({.a = -1, .b = 0, .rest_length = length_m});
    return s;
  }
  void from_particles(const particle_system& s, vec& x, vec& v) const {
    const Eigen::Vector3d p = s.x.col(0), pv = s.v.col(0);
    x[0] = std::atan2(p.x(), -p.y());
    v[0] = (p.x() * pv.y() - p.y() * pv.x()) / p.head<2>().squaredNorm();
  }
};

}  // namespace stepbench

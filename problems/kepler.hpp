#pragma once
// The lecture's gravitation (forces: f = G m M / r^2) as an orbit: a body of
// mass m around a fixed mass, F = -gm m r / |r|^3 (gm = G M), in the orbital plane, started
// at periapsis as in the DETEST orbit problems (Hull, Enright, Fellen and Sedgwick, SIAM J.
// Numer. Anal. 9 (1972), class D):
//   r0 = (a (1 - e), 0),   v0 = (0, sqrt(gm (1 + e) / (a (1 - e)))).
// The default e = 0.9 passes periapsis at a tenth of the semi-major axis, 19 times faster
// than at apoapsis: a fixed step must resolve that passage or the orbit gains or loses
// energy there. Horizon: 3 orbital periods.
//
// Closed form through Kepler's equation, solved to round-off (problems/exact/kepler.hpp).
// Energy E = m |v|^2 / 2 - gm m / |r| and angular momentum L = m (x v_y - y v_x) are
// conserved; both are recorded with their errors.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <string>

#include "core/concepts.hpp"
#include "problems/exact/kepler.hpp"

namespace stepbench {

struct kepler {
  static constexpr std::string_view name = "kepler";
  static constexpr std::string_view description =
      "body around a fixed mass, F = -gm m r/|r|^3, e = 0.9, from periapsis";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = false;
  static constexpr int dim() { return 2; }
  using vec = Eigen::Vector2d;
  using jacobian_matrix = Eigen::Matrix2d;

  double eccentricity = 0.9;
  double semi_major_axis = 1.0;
  double gm = 1.0;
  double mass_kg = 1.0;
  double orbits = 3.0;

  static constexpr auto parameters() {
    using p = param<kepler>;
    return std::array{
        p{"eccentricity", &kepler::eccentricity, "1", "orbital eccentricity", in_closed_open(0.0, 1.0)},
        p{"semi_major_axis", &kepler::semi_major_axis, "m", "semi-major axis a", positive},
        p{"gm", &kepler::gm, "m^3/s^2", "gravitational parameter G M of the fixed mass", positive},
        p{"mass_kg", &kepler::mass_kg, "kg", "mass of the orbiting body", positive},
        p{"orbits", &kepler::orbits, "1", "default horizon in orbital periods", positive},
    };
  }
  exact::kepler_orbit orbit() const { return {gm, semi_major_axis, eccentricity}; }

  double mass() const { return mass_kg; }
  double period() const { return orbit().period(); }
  double horizon() const { return orbits * period(); }

  // F = -gm m r / |r|^3: one square root and one division.
  void force(double, const vec& x, const vec&, vec& f) const {
    const double r2 = x.squaredNorm();
    f = (-gm * mass_kg / (r2 * std::sqrt(r2))) * x;
  }
  // dF/dx = -gm m (I - 3 u u^T) / |r|^3 with u = r / |r|; dF/dv = 0.
  jacobian_matrix make_jacobian() const { return jacobian_matrix::Zero(); }
  void jacobian(double, const vec& x, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    const double r2 = x.squaredNorm(), r3 = r2 * std::sqrt(r2);
    dfdx = (-gm * mass_kg / r3) * (jacobian_matrix::Identity() - (3.0 / r2) * (x * x.transpose()));
    dfdv.setZero();
  }

  phase<vec> initial() const {
    const auto s = orbit().initial();
    return {vec(s.x, s.y), vec(s.vx, s.vy)};
  }
  phase<vec> exact(double t) const {
    const auto s = orbit().at(t);
    return {vec(s.x, s.y), vec(s.vx, s.vy)};
  }
  double energy(const vec& x, const vec& v) const { return mass_kg * (0.5 * v.squaredNorm() - gm / x.norm()); }
  double angular_momentum(const vec& x, const vec& v) const { return mass_kg * (x.x() * v.y() - x.y() * v.x()); }

  // What happened in the scene where a run stopped (core/concepts.hpp, has_scene_report):
  // an orbit whose radius fell well inside the periapsis a (1 - e) has collapsed into the
  // centre, where the force is singular (implicit Euler's numerical damping drains an
  // eccentric orbit's energy until it does).
  std::string scene_report(double t, const vec& x, const vec& v) const {
    const double r = x.norm(), periapsis = semi_major_axis * (1.0 - eccentricity);
    const auto s0 = initial();
    const std::string where = r < 0.5 * periapsis   ? "the orbit collapsed"
                              : r < 1.5 * periapsis ? "at periapsis"
                                                    : "on the orbit";
    return fmt::format("{}: r = {:.3g} m at t = {:.4g} s (periapsis {:.3g} m), energy {:.3g} J against {:.3g} J", where,
                       r, t, periapsis, energy(x, v), energy(s0.x, s0.v));
  }
};

}  // namespace stepbench

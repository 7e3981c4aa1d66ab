#pragma once
// The constraint view of a scene: what the position-based methods (integrators/xpbd.hpp)
// step instead of forces. Shipping engines step ropes, cloth and ragdolls as particles
// joined by distance constraints (Macklin, Mueller & Chentanez, "XPBD: Position-Based
// Simulation of Compliant Constrained Dynamics", MIG 2016); a problem that declares this
// view is run with them, one that does not is listed as not applicable.
//
// A rigid link is a constraint of compliance 0; a spring of stiffness k_s is one of
// compliance 1 / k_s (XPBD eq. 4: the potential U = C^2 / (2 alpha) is the spring's
// k_s (|d| - L0)^2 / 2), its damper of coefficient k_d the constraint's damping (XPBD
// sec. 3.5: R = beta C'^2 / 2, with beta = k_d). External forces are the scene's
// uniform acceleration (gravity): the scenes with a constraint view have no others.
#include <Eigen/Core>
#include <concepts>
#include <vector>

namespace stepbench {

// C(x) = |x_b - x_a| - rest_length; a = -1 joins b to the fixed point `anchor`.
struct distance_constraint {
  int a = -1;
  int b = 0;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
  double rest_length = 0.0;  // [m]
  double compliance = 0.0;   // alpha [m/N]: 0 is a rigid link
  double damping = 0.0;      // beta [N s/m], along the constraint
};

// Particles in 3-D (a column each) and the constraints between them.
struct particle_system {
  Eigen::Matrix3Xd x;
  Eigen::Matrix3Xd v;
  Eigen::VectorXd inverse_mass;                            // 1 / m [1/kg]; 0 pins the particle
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // external (gravity) [m/s^2]
  std::vector<distance_constraint> constraints;
};

// A problem with a constraint view: its particles at a state of its own coordinates,
// and back (the run is recorded, and measured, in the problem's coordinates).
template <class P>
concept has_constraint_view = requires(const P& p, const typename P::vec& x, typename P::vec& out,
                                       const particle_system& s) {
  { p.particles(x, x) } -> std::same_as<particle_system>;
  {p.from_particles(s, out, out)};
};

// A problem whose positions are observed (has_observed_positions) and which position-based
// methods step as particles (has_constraint_view): `observe_particles` writes the
// positions and velocities those particles draw, in observe's layout. XPBD is scored on
// them, not on the state read back from them (which puts the bobs back on exact links).
template <class P>
concept has_drawn_particles = requires(const P& p, const particle_system& s, Eigen::VectorXd& out) {
  {p.observe_particles(s, out, out)};
};

// The distance a constraint holds: from its particle a (or its anchor) to particle b.
inline double constraint_length(const particle_system& s, const distance_constraint& c) {
  const Eigen::Vector3d pa = c.a < 0 ? c.anchor : Eigen::Vector3d(s.x.col(c.a));
  return (s.x.col(c.b) - pa).norm();
}

// The largest |C| / rest length over the constraints: how far the links are from their
// lengths (for a compliant constraint, its stretch).
inline double constraint_violation(const particle_system& s) {
  double worst = 0.0;
  for (const auto& c : s.constraints)
    worst = std::max(worst, std::abs(constraint_length(s, c) - c.rest_length) / c.rest_length);
  return worst;
}

}  // namespace stepbench

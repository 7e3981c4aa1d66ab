#pragma once
// A mass on a spring and damper, F = -k_s x - k_d v, i.e. m x'' + k_d x' + k_s x = 0
// (the lecture's springs): the physics of two scenes, `damped_spring` (the lecture's RK4
// example, below) and `stiff_spring` (problems/stiff_spring.hpp), which differ only in
// their defaults: a scene is a struct of defaults, the physics is written once here.
//
// Closed form for every damping regime in one expression. With gamma = k_d / (2m),
// w0^2 = k_s / m, D = gamma^2 - w0^2 and s = sqrt|D|:
//   x(t) = x0 Phi(t) + (v0 + gamma x0) Psi(t),   v(t) = v0 (Phi - gamma Psi) - w0^2 x0 Psi,
//   Phi = e^{-gamma t} C(t), Psi = e^{-gamma t} S(t),
// with (C, S) = (cos st, sin(st)/s) under-damped (D < 0), (1, t) critical (D = 0),
// (cosh st, sinh(st)/s) over-damped (D > 0). Since C' = D S and S' = C,
//   Phi' = -gamma Phi + D Psi, Psi' = -gamma Psi + Phi.
// sin(st)/s tends to t as s -> 0, so near-critical damping loses no accuracy (on the
// over-damped side through expm1). Away from critical damping the over-damped motion is
// evaluated as c1 e^{r1 t} + c2 e^{r2 t} with the roots written without cancellation, so
// heavy damping (gamma >> w0) keeps its digits in v too.
#include <Eigen/Core>
#include <cmath>

#include "core/concepts.hpp"
#include "core/constraints.hpp"

namespace stepbench {

template <class Scene>
struct spring_damper {
  static constexpr std::string_view name = Scene::name;
  static constexpr std::string_view description = Scene::description;
  static constexpr int dim() { return 1; }
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = true;
  using vec = Eigen::Matrix<double, 1, 1>;
  using jacobian_matrix = Eigen::Matrix<double, 1, 1>;

  double k_s = Scene::k_s;
  double k_d = Scene::k_d;
  double mass_kg = Scene::mass_kg;
  double x0 = Scene::x0;
  double v0 = Scene::v0;
  double duration = Scene::duration;

  static constexpr auto parameters() {
    using p = param<spring_damper>;
    return std::array{
        p{"k_s", &spring_damper::k_s, "N/m", "spring stiffness", positive},
        p{"k_d", &spring_damper::k_d, "N s/m", "damping coefficient", non_negative},
        p{"mass_kg", &spring_damper::mass_kg, "kg", "mass", positive},
        p{"x0", &spring_damper::x0, "m", "initial displacement"},
        p{"v0", &spring_damper::v0, "m/s", "initial velocity"},
        p{"duration", &spring_damper::duration, "s", "default horizon", positive},
    };
  }

  double mass() const { return mass_kg; }
  void force(double, const vec& x, const vec& v, vec& f) const { f = -k_s * x - k_d * v; }
  // dF/dx = -k_s, dF/dv = -k_d.
  jacobian_matrix make_jacobian() const { return jacobian_matrix::Zero(); }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx(0, 0) = -k_s;
    dfdv(0, 0) = -k_d;
  }
  phase<vec> initial() const { return {vec(x0), vec(v0)}; }
  double horizon() const { return duration; }

  double gamma() const { return k_d / (2.0 * mass_kg); }
  double omega0_sq() const { return k_s / mass_kg; }

  phase<vec> exact(double t) const {
    const double g = gamma(), w0 = std::sqrt(omega0_sq());
    const double d = (g - w0) * (g + w0);  // gamma^2 - w0^2 without overflow or cancellation
    const double b = v0 + g * x0;
    double phi, psi;
    if (d < 0.0) {
      const double s = std::sqrt(-d), decay = std::exp(-g * t);
      phi = decay * std::cos(s * t);
      psi = decay * std::sin(s * t) / s;
    } else if (d == 0.0) {
      const double decay = std::exp(-g * t);
      phi = decay;
      psi = decay * t;
    } else {
      // Roots r1 = -w0^2 / (s + gamma) (slow, written without cancellation) and
      // r2 = -(s + gamma) (fast).
      const double s = std::sqrt(d), r1 = -omega0_sq() / (s + g), r2 = -(s + g);
      const double slow = std::exp(r1 * t), fast = std::exp(r2 * t);
      if (2.0 * s * t >= 1.0) {
        // Away from critical damping: x = c1 e^{r1 t} + c2 e^{r2 t}. The Phi/Psi form
        // below would take v as a difference of terms of size gamma that nearly cancel
        // when gamma >> w0 (heavy damping).
        const double c1 = (v0 - r2 * x0) / (2.0 * s), c2 = (r1 * x0 - v0) / (2.0 * s);
        return {vec(c1 * slow + c2 * fast), vec(r1 * c1 * slow + r2 * c2 * fast)};
      }
      phi = 0.5 * (slow + fast);
      // slow - fast = fast (e^{2st} - 1): expm1 keeps the digits that the difference
      // would cancel near critical damping (s t small).
      psi = fast * std::expm1(2.0 * s * t) / (2.0 * s);
    }
    // v = x0 Phi' + b Psi' = x0 (d - gamma^2) Psi + v0 (Phi - gamma Psi), and d - gamma^2
    // = -w0^2: written so, no terms of size gamma cancel (they would when gamma t is small
    // and gamma large).
    const double x = x0 * phi + b * psi;
    const double v = v0 * (phi - g * psi) - omega0_sq() * x0 * psi;
    return {vec(x), vec(v)};
  }
  // Mechanical energy; the damper dissipates it, so it is compared with the exact
  // solution's energy, not with E(0).
  double energy(const vec& x, const vec& v) const {
    return 0.5 * mass_kg * v.squaredNorm() + 0.5 * k_s * x.squaredNorm();
  }

  // The constraint view: the body a particle at (L + x, 0, 0) on a distance constraint of
  // rest length L = 1 m to the origin, compliance 1 / k_s, damping k_d. Along the axis
  // C = x is linear, so one XPBD pass is one backward Euler step (integrators/xpbd.hpp).
  static constexpr double view_rest_length = 1.0;
  particle_system particles(const vec& x, const vec& v) const {
    particle_system s;
    s.x = Eigen::Vector3d(view_rest_length + x[0], 0.0, 0.0);
    s.v = Eigen::Vector3d(v[0], 0.0, 0.0);
    s.inverse_mass = Eigen::VectorXd::Constant(1, 1.0 / mass_kg);
    s.constraints.push_back(
        {.a = -1, .b = 0, .rest_length = view_rest_length, .compliance = 1.0 / k_s, .damping = k_d});
    return s;
  }
  void from_particles(const particle_system& s, vec& x, vec& v) const {
    x[0] = s.x(0, 0) - view_rest_length;
    v[0] = s.v(0, 0);
  }
};

// The lecture's RK4 example (springs, integration): a unit mass, k = 10, b = 1.
struct damped_spring_scene {
  static constexpr std::string_view name = "damped_spring";
  static constexpr std::string_view description = "mass on a spring and damper (lecture's RK4 example)";
  static constexpr double k_s = 10.0, k_d = 1.0, mass_kg = 1.0, x0 = 1.0, v0 = 0.0, duration = 10.0;
};
using damped_spring = spring_damper<damped_spring_scene>;

}  // namespace stepbench

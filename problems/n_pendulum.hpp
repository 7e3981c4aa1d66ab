#pragma once
// An N-link pendulum: `links` rigid massless rods of length l, a bob of mass m at the end
// of each, the first hung from a fixed pivot, in the vertical plane under g. The scene of
// Mueller's "pendulum challenge" (Ten Minute Physics, 2022: 3 links of 1 kg and 0.3 m,
// g = 10 m/s^2, a 60 Hz frame, released from rest with every link horizontal), the
// defaults here. The motion is chaotic: nearby starts part exponentially.
//
// Two views of one scene:
// - generalized coordinates, for every force-based method: the state is the links'
//   absolute angles theta_i from the downward vertical. Bob k is at
//   p_k = sum_{i <= k} l (sin theta_i, -cos theta_i). With mu_ij = m (N - max(i, j)) the
//   mass hung at or below both links i and j (0-based), Lagrange's equations are
//     sum_j mu_ij l^2 cos(theta_i - theta_j) theta_j''
//       = -sum_j mu_ij l^2 sin(theta_i - theta_j) theta_j'^2 - mu_ii g l sin theta_i,
//   M(theta) theta'' = r(theta, theta'), M symmetric positive definite (the kinetic
//   energy is theta'^T M theta' / 2). The integrators see m = 1 and F = theta'' (there is
//   no one inertia to factor out): each force evaluation assembles M and solves it by
//   Cholesky, in matrices of at most max_links rows held on the stack (no allocation).
// - the constraint view (core/constraints.hpp), for the position-based methods: N
//   particles joined by rigid distance constraints, the first to the pivot.
// Errors are measured on the bobs' Cartesian positions in m (observe, below), the same
// for both views; the truth comes from the references in generalized coordinates.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "core/concepts.hpp"
#include "core/constraints.hpp"

namespace stepbench {

struct n_pendulum {
  static constexpr std::string_view name = "n_pendulum";
  static constexpr std::string_view description =
      "pendulum of N rigid links (the pendulum challenge: 3 links, horizontal)";
  static constexpr std::string_view position_unit = "m";   // of the bobs (observe)
  static constexpr bool force_depends_on_velocity = true;  // the centripetal terms
  static constexpr int max_links = 16;
  using vec = Eigen::VectorXd;
  using small_matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_links, max_links>;
  using small_vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_links, 1>;

  double links = 3;
  double mass_kg = 1.0;
  double length_m = 0.3;
  double gravity = 10.0;
  double theta0_deg = 90.0;
  double duration = 32.0 / 60.0;  // 32 frames at 60 Hz: the ladder's coarsest level is the frame

  static constexpr auto parameters() {
    using p = param<n_pendulum>;
    return std::array{
        p{"links", &n_pendulum::links, "1", "number of links (a bob at the end of each)", whole_from(1, max_links)},
        p{"mass_kg", &n_pendulum::mass_kg, "kg", "mass of each bob", positive},
        p{"length_m", &n_pendulum::length_m, "m", "length of each link", positive},
        p{"gravity", &n_pendulum::gravity, "m/s^2", "gravitational acceleration, along -y", positive},
        p{"theta0_deg", &n_pendulum::theta0_deg, "deg", "release angle of every link from the downward vertical"},
        p{"duration", &n_pendulum::duration, "s", "default horizon", positive},
    };
  }

  int count() const { return static_cast<int>(links); }
  int dim() const { return count(); }
  double mass() const { return 1.0; }
  double horizon() const { return duration; }
  phase<vec> initial() const {
    return {vec::Constant(count(), theta0_deg * std::numbers::pi / 180.0), vec::Zero(count())};
  }

  // theta'' = M^{-1} r (the header's equations; l^2 divided out of both sides).
  // The angle differences from each angle's sine and cosine (2N calls, not 2N^2):
  // cos(a - b) = cos a cos b + sin a sin b, sin(a - b) = sin a cos b - cos a sin b.
  // Out of line: 2N sines and cosines and a Cholesky solve cost far more than a call,
  // and the flattened loops (core/flatten.hpp) inlined this body into every stage of
  // every method, a third of this problem's unit (the largest of the build).
  [[gnu::noinline]] void force(double, const vec& x, const vec& v, vec& f) const {
    const int n = count();
    small_vector sn(n), cs(n), r(n);
    for (int i = 0; i < n; ++i) sn[i] = std::sin(x[i]), cs[i] = std::cos(x[i]);
    small_matrix m(n, n);
    for (int i = 0; i < n; ++i) {
      r[i] = -mass_kg * (n - i) * (gravity / length_m) * sn[i];
      for (int j = 0; j < n; ++j) {
        const double mu = mass_kg * (n - std::max(i, j));
        m(i, j) = mu * (cs[i] * cs[j] + sn[i] * sn[j]);
        r[i] -= mu * (sn[i] * cs[j] - cs[i] * sn[j]) * v[j] * v[j];
      }
    }
    f = Eigen::LLT<small_matrix>(m).solve(r);
  }

  // Kinetic and gravitational energy of the bobs (the rods are massless and rigid), from
  // their positions and velocities (observe, below).
  double energy(const vec& x, const vec& v) const {
    Eigen::VectorXd pos(observed_dim()), vel(observed_dim());
    observe(x, v, pos, vel);
    double e = 0.0;
    for (int i = 0; i < count(); ++i)
      e += mass_kg * (0.5 * vel.segment<2>(2 * i).squaredNorm() + gravity * pos[2 * i + 1]);
    return e;
  }

  // The bobs' positions and velocities, (x, y) a bob: what errors are measured on.
  int observed_dim() const { return 2 * count(); }
  int body_dim() const { return 2; }  // errors are the worst bob's
  void observe(const vec& x, const vec& v, Eigen::VectorXd& pos, Eigen::VectorXd& vel) const {
    double px = 0.0, py = 0.0, vx = 0.0, vy = 0.0;
    for (int i = 0; i < count(); ++i) {
      px += length_m * std::sin(x[i]);
      py -= length_m * std::cos(x[i]);
      vx += length_m * std::cos(x[i]) * v[i];
      vy += length_m * std::sin(x[i]) * v[i];
      pos.segment<2>(2 * i) << px, py;
      vel.segment<2>(2 * i) << vx, vy;
    }
  }

  // The constraint view: bob i a particle (z = 0), rigid links.
  particle_system particles(const vec& x, const vec& v) const {
    particle_system s;
    const int n = count();
    s.x.setZero(3, n);
    s.v.setZero(3, n);
    s.inverse_mass = Eigen::VectorXd::Constant(n, 1.0 / mass_kg);
    s.acceleration = {0.0, -gravity, 0.0};
    Eigen::VectorXd pos(2 * n), vel(2 * n);
    observe(x, v, pos, vel);
    for (int i = 0; i < n; ++i) {
      s.x.col(i).head<2>() = pos.segment<2>(2 * i);
      s.v.col(i).head<2>() = vel.segment<2>(2 * i);
      s.constraints.push_back({.a = i - 1, .b = i, .rest_length = length_m});
    }
    return s;
  }
  // The bobs as the particles draw them, in observe's layout (bob i: particle i's x, y):
  // what XPBD is scored on, wherever its links have stretched.
  void observe_particles(const particle_system& s, Eigen::VectorXd& pos, Eigen::VectorXd& vel) const {
    for (int i = 0; i < count(); ++i) {
      pos.segment<2>(2 * i) = s.x.col(i).head<2>();
      vel.segment<2>(2 * i) = s.v.col(i).head<2>();
    }
  }
  // Each link's angle from its direction, theta = atan2(d_x, -d_y), and its rate from
  // d x d' = |d|^2 theta' (d = l (sin theta, -cos theta), d' = l theta' (cos theta, sin theta)).
  void from_particles(const particle_system& s, vec& x, vec& v) const {
    Eigen::Vector2d p_prev = Eigen::Vector2d::Zero(), v_prev = Eigen::Vector2d::Zero();
    for (int i = 0; i < count(); ++i) {
      const Eigen::Vector2d d = s.x.col(i).head<2>() - p_prev, dd = s.v.col(i).head<2>() - v_prev;
      x[i] = std::atan2(d.x(), -d.y());
      v[i] = (d.x() * dd.y() - d.y() * dd.x()) / d.squaredNorm();
      p_prev = s.x.col(i).head<2>();
      v_prev = s.v.col(i).head<2>();
    }
  }
};

}  // namespace stepbench

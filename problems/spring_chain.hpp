#pragma once
// A rope: `masses` point masses in 3-D joined in a line by the lecture's springs with
// rest length and a damper along each spring (the lecture's springs),
//   F_i += k_s (|d| - L0) d/|d| + k_d ((w . u) u),   d = x_{i+1} - x_i, u = d / |d|,
//   w = v_{i+1} - v_i, and the opposite force on mass i+1,
// under gravity (-z), the first mass pinned (its force is the pin's: zero), released
// at rest from a horizontal line at rest length along +x. No closed form: the truth
// comes from the references. The state size is a run-time parameter, so the state is
// an Eigen::VectorXd of 3 * masses coordinates; the force allocates nothing.
//
// Defaults: 32 masses, a 1 m rope of 1 kg (m = 1/32 kg a mass, L0 = 1/31 m), k_s =
// 1e4 N/m, k_d = 0.1 N s/m. The fastest mode of a chain of springs k and masses m has
// w_max ~ 2 sqrt(k / m) = 1131 rad/s, so a 60 Hz frame is w_max dt = 18.9: past every
// explicit method's limit (RK4's is 2.83), as in a game's rope. The weight stretches the
// top segment by m g N / k_s = 1 mm (3 % of L0); the dampers give that mode a damping
// ratio of about k_d w_max / (2 k_s) = 0.006. The horizon is 32 frames at 60 Hz.
//
// The force Jacobians are analytic and banded (problems/spring_chain.hpp's jacobian):
// with the coordinates of mass i at 3i..3i+2, a spring couples only neighbouring masses,
// so dF/dx and dF/dv have 5 sub- and 5 super-diagonals and the implicit methods solve in
// O(n) (core/band_matrix.hpp), not through a dense O(n^3) solve.
#include <Eigen/Core>

#include "core/band_matrix.hpp"
#include "core/concepts.hpp"
#include "core/constraints.hpp"

namespace stepbench {

struct spring_chain {
  static constexpr std::string_view name = "spring_chain";
  static constexpr std::string_view description = "rope of point masses on damped springs, first pinned, under gravity";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = true;
  using vec = Eigen::VectorXd;
  using jacobian_matrix = band_matrix;
  static constexpr int bandwidth = 5;  // 3 coordinates per mass: couplings reach the next mass's last one

  double masses = 32;
  double rope_mass_kg = 1.0;
  double rope_length_m = 1.0;
  double k_s = 1e4;
  double k_d = 0.1;
  double gravity = 9.8;
  double duration = 32.0 / 60.0;

  static constexpr auto parameters() {
    using p = param<spring_chain>;
    return std::array{
        p{"masses", &spring_chain::masses, "1", "number of point masses (the first is pinned)", whole_from(2, 1 << 20)},
        p{"rope_mass_kg", &spring_chain::rope_mass_kg, "kg", "total mass, shared equally", positive},
        p{"rope_length_m", &spring_chain::rope_length_m, "m", "rest length of the whole rope", positive},
        p{"k_s", &spring_chain::k_s, "N/m", "stiffness of each spring", positive},
        p{"k_d", &spring_chain::k_d, "N s/m", "damping of each spring, along it", non_negative},
        p{"gravity", &spring_chain::gravity, "m/s^2", "magnitude of g, along -z"},
        p{"duration", &spring_chain::duration, "s", "default horizon", positive},
    };
  }

  int count() const { return static_cast<int>(masses); }
  int dim() const { return 3 * count(); }
  int body_dim() const { return 3; }  // (x, y, z) a mass: errors are the worst mass's
  double mass() const { return rope_mass_kg / masses; }
  double rest_length() const { return rope_length_m / (masses - 1); }
  double horizon() const { return duration; }

  phase<vec> initial() const {
    vec x = vec::Zero(dim());
    for (int i = 0; i < count(); ++i) x[3 * i] = i * rest_length();
    return {x, vec::Zero(dim())};
  }

  // One pass over the masses: each spring is computed once, its force added to the mass
  // before it and carried (negated) to the mass after it; f is written once per mass.
  // Out of line: a pass over 32 masses (a square root and a division each) costs far
  // more than a call, and the flattened loops (core/flatten.hpp) inlined it into every
  // stage of every method.
  [[gnu::noinline]] void force(double, const vec& x, const vec& v, vec& f) const {
    const double weight = mass() * gravity, l0 = rest_length();
    const int n = count();
    Eigen::Vector3d carry = Eigen::Vector3d::Zero();  // force of the spring before mass i
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d fi = carry;
      fi.z() -= weight;
      if (i + 1 < n) {
        const Eigen::Vector3d d = x.segment<3>(3 * i + 3) - x.segment<3>(3 * i);
        const double len = d.norm();
        const Eigen::Vector3d u = d * (1.0 / len);
        const double w = (v.segment<3>(3 * i + 3) - v.segment<3>(3 * i)).dot(u);
        const Eigen::Vector3d fs = (k_s * (len - l0) + k_d * w) * u;  // on mass i, towards i + 1
        fi += fs;
        carry = -fs;
      }
      f.segment<3>(3 * i) = fi;
    }
    f.segment<3>(0).setZero();  // the pin holds the first mass
  }

  jacobian_matrix make_jacobian() const { return band_matrix(dim(), bandwidth, bandwidth); }

  // With f the force of one spring on mass i (d = x_{i+1} - x_i, w = v_{i+1} - v_i,
  // l = |d|, u = d / l, P = I - u u^T):
  //   df/dd = k_s [(1 - L0/l) I + (L0/l) u u^T] + (k_d / l) [u w^T P + (w . u) P],
  //   df/dw = k_d u u^T;
  // mass i gets +f (d depends on x_i with -I), mass i+1 gets -f, so each spring adds
  // -A, +A, +A, -A to the blocks (i,i), (i,i+1), (i+1,i), (i+1,i+1) of dF/dx (A = df/dd),
  // and the same with B = df/dw to dF/dv. The pinned mass's rows are zero.
  void jacobian(double, const vec& x, const vec& v, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx.set_zero();
    dfdv.set_zero();
    const double l0 = rest_length();
    for (int s = 0; s + 1 < count(); ++s) {
      const Eigen::Vector3d d = x.segment<3>(3 * s + 3) - x.segment<3>(3 * s);
      const Eigen::Vector3d w = v.segment<3>(3 * s + 3) - v.segment<3>(3 * s);
      const double len = d.norm();
      const Eigen::Vector3d u = d / len;
      const Eigen::Matrix3d uu = u * u.transpose();
      const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - uu;
      const Eigen::Matrix3d a = k_s * ((1.0 - l0 / len) * Eigen::Matrix3d::Identity() + (l0 / len) * uu) +
                                (k_d / len) * (u * (w.transpose() * p) + w.dot(u) * p);
      const Eigen::Matrix3d b = k_d * uu;
      add_spring_blocks(dfdx, s, a);
      add_spring_blocks(dfdv, s, b);
    }
    for (int r = 0; r < 3; ++r)  // the pinned mass
      for (int c = std::max(0, r - bandwidth); c <= std::min(dim() - 1, r + bandwidth); ++c)
        dfdx(r, c) = dfdv(r, c) = 0.0;
  }

  // The constraint view: a particle a mass (the first pinned: inverse mass 0), each
  // spring a distance constraint of compliance 1 / k_s and damping k_d.
  particle_system particles(const vec& x, const vec& v) const {
    particle_system s;
    s.x = Eigen::Map<const Eigen::Matrix3Xd>(x.data(), 3, count());
    s.v = Eigen::Map<const Eigen::Matrix3Xd>(v.data(), 3, count());
    s.inverse_mass = Eigen::VectorXd::Constant(count(), 1.0 / mass());
    s.inverse_mass[0] = 0.0;
    s.acceleration = {0.0, 0.0, -gravity};
    for (int i = 0; i + 1 < count(); ++i)
      s.constraints.push_back(
          {.a = i, .b = i + 1, .rest_length = rest_length(), .compliance = 1.0 / k_s, .damping = k_d});
    return s;
  }
  void from_particles(const particle_system& s, vec& x, vec& v) const {
    x = Eigen::Map<const vec>(s.x.data(), dim());
    v = Eigen::Map<const vec>(s.v.data(), dim());
  }

  // Kinetic, gravitational and spring energy; the dampers dissipate it.
  double energy(const vec& x, const vec& v) const {
    const double m = mass(), l0 = rest_length();
    double e = 0.5 * m * v.squaredNorm();
    for (int i = 0; i < count(); ++i) e += m * gravity * x[3 * i + 2];
    for (int i = 0; i + 1 < count(); ++i) {
      const double stretch = (x.segment<3>(3 * i + 3) - x.segment<3>(3 * i)).norm() - l0;
      e += 0.5 * k_s * stretch * stretch;
    }
    return e;
  }

 private:
  static void add_spring_blocks(jacobian_matrix& j, int s, const Eigen::Matrix3d& a) {
    const int i = 3 * s, k = 3 * s + 3;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        j(i + r, i + c) -= a(r, c);
        j(i + r, k + c) += a(r, c);
        j(k + r, i + c) += a(r, c);
        j(k + r, k + c) -= a(r, c);
      }
  }
};

}  // namespace stepbench

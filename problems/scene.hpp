#pragma once
// A user's scene: point masses and only the force elements the scene declares, read from
// a scene file (problems/scene_file.hpp, docs/scenes.md): springs with dampers along
// their axis, a uniform gravity field, drag, pairwise attraction. The forces are data,
// one array a kind, each looped over (no virtual call an element, nothing allocated in a
// step), with analytic Jacobians.
//
// The state holds the moving masses only, D coordinates each (D = 1, 2 or 3), in file
// order: a fixed mass never moves, so it is a constant of the force, not a coordinate
// (a spring to a fixed mass is a spring to a point). Masses differ from one another, so
// the problem's mass() is 1 and force() returns each mass's acceleration F_i / m_i: the
// integrators' M is the identity, their Jacobians those of the accelerations.
//
// The arithmetic is the built-in problems', in their order, where a scene re-expresses
// one (examples/scenes/): a spring's force (k (|d| - L0) + c (w . u)) u, u = d / |d|,
// is problems/spring_chain.hpp's; each mass's sum starts from its weight m g and takes
// the springs in file order, then drag, then attraction; the sum is scaled by 1 / m
// once. So those scenes step bit for bit as the built-ins do (tests/test_scenes.cpp).
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/band_matrix.hpp"
#include "core/concepts.hpp"

namespace stepbench {

// What a scene file declares (problems/scene_file.cpp reads and checks it), with the
// masses' indices resolved: the element arrays the force loops over.
struct scene_data {
  std::string name, description, path;
  long name_line = 1, name_column = 1;  // where the file declares the name, for a refusal of it
  int dim = 0;                          // coordinates a mass: 1, 2 or 3
  double horizon = 0.0;
  std::array<double, 3> gravity{};
  bool has_gravity = false;

  struct mass_point {
    std::string name;
    double mass = 0.0;  // 0 for a fixed mass
    bool fixed = false;
    std::array<double, 3> position{}, velocity{};
  };
  std::vector<mass_point> masses;  // as declared

  // A spring's ends: a moving mass's index in the state (>= 0), or ~k for the k-th fixed
  // mass (a point).
  struct spring {
    int a = 0, b = 0;
    double stiffness = 0.0, damping = 0.0, rest_length = 0.0;
  };
  std::vector<spring> springs;  // as declared
  // The same springs as the force loops take them, without a branch an end: those with a
  // fixed end (a: the moving mass, b: the fixed point's index; d = point - x_a, which
  // negates the declared d exactly when the fixed end was declared first), then those
  // between two moving masses, each in file order.
  std::vector<spring> anchored, between_moving;

  // A wall: the half-space {x : normal . x >= offset}, the normal a unit vector (the file's
  // divided by its length, the offset with it), with the lecture's collision response and
  // Coulomb's friction on the impulse (contact_scene::resolve_contacts).
  struct plane {
    std::array<double, 3> normal{};
    double offset = 0.0;
    double restitution = 1.0;      // k_r
    double friction = 0.0;         // mu_k, Coulomb's kinetic coefficient
    double static_friction = 0.0;  // mu_s, Coulomb's static coefficient
    double tangential_loss = 0.0;  // the lecture's k_f
  };
  std::vector<plane> planes;

  double drag_linear = 0.0, drag_quadratic = 0.0;
  bool has_drag = false;
  double attraction_G = 0.0;
  bool has_attraction = false;

  // Derived: the moving masses' inverse masses and masses (state order), the fixed masses'
  // positions and masses, and where each declared mass went (>= 0 moving, ~k fixed).
  std::vector<double> inverse_mass, moving_mass;
  std::vector<std::array<double, 3>> fixed_position;
  std::vector<double> fixed_mass;  // for attraction; 0 for a fixed mass declared without one
  std::vector<int> slot;

  int moving() const { return static_cast<int>(moving_mass.size()); }
};

struct scene {
  static constexpr std::string_view name = "scene";
  static constexpr std::string_view description = "a scene from a file (docs/scenes.md)";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = true;
  using vec = Eigen::VectorXd;
  using jacobian_matrix = band_matrix;

  std::shared_ptr<const scene_data> data = std::make_shared<const scene_data>(one_mass());

  double stiffness_scale = 1.0;
  double damping_scale = 1.0;
  double gravity_scale = 1.0;
  double drag_scale = 1.0;
  double G_scale = 1.0;
  double duration = 1.0;

  scene() = default;
  explicit scene(std::shared_ptr<const scene_data> d) : data(std::move(d)), duration(data->horizon) {}

  static constexpr auto parameters() {
    using p = param<scene>;
    return std::array{
        p{"stiffness_scale", &scene::stiffness_scale, "1", "multiplies every spring's stiffness", non_negative},
        p{"damping_scale", &scene::damping_scale, "1", "multiplies every spring's damping", non_negative},
        p{"gravity_scale", &scene::gravity_scale, "1", "multiplies the gravity field", finite},
        p{"drag_scale", &scene::drag_scale, "1", "multiplies both drag coefficients", non_negative},
        p{"G_scale", &scene::G_scale, "1", "multiplies the attraction constant G", non_negative},
        p{"duration", &scene::duration, "s", "default horizon (the file's horizon)", positive},
    };
  }
  // The defaults `stepbench list` and the study report: the file's, not a default scene's.
  scene defaults() const { return scene(data); }

  std::string_view label() const { return data->name; }
  std::string_view summary() const { return data->description; }
  int count() const { return data->moving(); }
  int dim() const { return data->dim * count(); }
  int body_dim() const { return data->dim; }  // errors are the worst moving mass's
  double mass() const { return 1.0; }         // force() returns accelerations (see above)
  double horizon() const { return duration; }

  phase<vec> initial() const {
    const int d = data->dim;
    vec x(dim()), v(dim());
    for (const auto& m : data->masses) {
      if (m.fixed) continue;
      const int i = data->slot[static_cast<std::size_t>(&m - data->masses.data())];
      for (int c = 0; c < d; ++c) x[d * i + c] = m.position[c], v[d * i + c] = m.velocity[c];
    }
    return {x, v};
  }

  // Out of line, as spring_chain's: a pass over the elements costs far more than a call,
  // and the flattened loops (core/flatten.hpp) would inline all three dimensions' passes
  // into every stage of every method (the scenes' unit took 109 s to compile so).
  [[gnu::noinline]] void force(double, const vec& x, const vec& v, vec& f) const {
    switch (data->dim) {
      case 1:
        return force_in<1>(x, v, f);
      case 2:
        return force_in<2>(x, v, f);
      default:
        return force_in<3>(x, v, f);
    }
  }

  // Every coordinate of a moving mass couples to those of the masses it shares a spring
  // with (all of them under attraction): the band reaches the farthest such pair.
  jacobian_matrix make_jacobian() const {
    const int d = data->dim, n = count();
    int reach = 0;
    if (data->has_attraction) reach = n - 1;
    for (const auto& s : data->springs)
      if (s.a >= 0 && s.b >= 0) reach = std::max(reach, std::abs(s.a - s.b));
    const int band = reach == 0 ? d - 1 : d * reach + d - 1;
    return band_matrix(dim(), band, band);
  }
  [[gnu::noinline]] void jacobian(double, const vec& x, const vec& v, jacobian_matrix& dadx,
                                  jacobian_matrix& dadv) const {
    switch (data->dim) {
      case 1:
        return jacobian_in<1>(x, v, dadx, dadv);
      case 2:
        return jacobian_in<2>(x, v, dadx, dadv);
      default:
        return jacobian_in<3>(x, v, dadx, dadv);
    }
  }

  // Kinetic energy, the potentials of gravity (-m g . x), the springs (k (|d| - L0)^2 / 2)
  // and attraction (-G m_i m_j / r); dampers and drag dissipate it.
  double energy(const vec& x, const vec& v) const {
    switch (data->dim) {
      case 1:
        return energy_in<1>(x, v);
      case 2:
        return energy_in<2>(x, v);
      default:
        return energy_in<3>(x, v);
    }
  }

 private:
  template <int D>
  using point = Eigen::Matrix<double, D, 1>;

  static scene_data one_mass();  // problems/scene_file.cpp: a free unit mass, for scene{}

  template <int D>
  static point<D> fixed_point(const scene_data& s, int k) {
    return Eigen::Map<const point<D>>(s.fixed_position[static_cast<std::size_t>(k)].data());
  }
  // The position and velocity of a spring's end: a moving mass's, or a fixed point at rest.
  template <int D>
  static point<D> end_x(const scene_data& s, const vec& x, int e) {
    return e >= 0 ? point<D>(x.template segment<D>(D * e)) : fixed_point<D>(s, ~e);
  }
  template <int D>
  static point<D> end_v(const vec& v, int e) {
    return e >= 0 ? point<D>(v.template segment<D>(D * e)) : point<D>::Zero();
  }

  // The unit vector along d: on a line, its sign exactly (d (1 / |d|) need not be +-1:
  // 49 (1 / 49) < 1), as the built-in one-dimensional springs have it.
  template <int D>
  static point<D> axis(const point<D>& d, double len) {
    if constexpr (D == 1)
      return point<D>::Constant(d[0] >= 0.0 ? 1.0 : -1.0);
    else
      return d * (1.0 / len);
  }

  // One spring's force on its end a: (k (|d| - L0) + c (w . u)) u, k and c scaled; false
  // where the ends coincide off a line (no axis, no force). Inlined into the force's loops
  // (as a lambda it was a call a spring, a third of the force's time).
  template <int D>
  [[gnu::always_inline]] static bool spring_force(const point<D>& d, const point<D>& dv, const scene_data::spring& sp,
                                                  double ks, double cs, point<D>& fs) {
    const double len = D == 1 ? std::abs(d[0]) : d.norm();
    if (D > 1 && !(len > 0.0)) return false;
    const point<D> u = axis<D>(d, len);
    const double w = dv.dot(u);
    fs = ((sp.stiffness * ks) * (len - sp.rest_length) + (sp.damping * cs) * w) * u;
    return true;
  }

  template <int D>
  void force_in(const vec& x, const vec& v, vec& f) const {
    const scene_data& s = *data;
    const int n = count();
    // The weight m g of each moving mass (zero without a field).
    if (s.has_gravity) {
      point<D> g;
      for (int c = 0; c < D; ++c) g[c] = gravity_scale * s.gravity[static_cast<std::size_t>(c)];
      for (int i = 0; i < n; ++i) f.template segment<D>(D * i) = s.moving_mass[static_cast<std::size_t>(i)] * g;
    } else {
      f.setZero();
    }
    // The springs: (k (|d| - L0) + c (w . u)) u on end a, its opposite on b; those to a
    // fixed point first (a mass's sum meets its springs in file order where, as on a
    // rope pinned at its first mass, the anchored springs come first in the file).
    const double ks = stiffness_scale, cs = damping_scale;
    point<D> fs;
    for (const auto& sp : s.anchored) {
      const point<D> xa = x.template segment<D>(D * sp.a), va = v.template segment<D>(D * sp.a);
      if (spring_force<D>(fixed_point<D>(s, sp.b) - xa, -va, sp, ks, cs, fs)) f.template segment<D>(D * sp.a) += fs;
    }
    for (const auto& sp : s.between_moving) {
      const point<D> d = x.template segment<D>(D * sp.b) - x.template segment<D>(D * sp.a);
      const point<D> w = v.template segment<D>(D * sp.b) - v.template segment<D>(D * sp.a);
      if (!spring_force<D>(d, w, sp, ks, cs, fs)) continue;
      f.template segment<D>(D * sp.a) += fs;
      f.template segment<D>(D * sp.b) -= fs;
    }
    if (s.has_drag) {  // -(linear + quadratic |v|) v
      const double lin = s.drag_linear * drag_scale, quad = s.drag_quadratic * drag_scale;
      for (int i = 0; i < n; ++i) {
        const point<D> vi = v.template segment<D>(D * i);
        const double speed = D == 1 ? std::abs(vi[0]) : vi.norm();
        f.template segment<D>(D * i) -= (lin + quad * speed) * vi;
      }
    }
    if (s.has_attraction) attraction_force<D>(x, f);
    for (int i = 0; i < n; ++i) f.template segment<D>(D * i) *= s.inverse_mass[static_cast<std::size_t>(i)];
  }

  // G m_i m_j (x_j - x_i) / r^3 on i, its opposite on j: every pair of moving masses once,
  // then each moving mass and each fixed one.
  template <int D>
  void attraction_force(const vec& x, vec& f) const {
    const scene_data& s = *data;
    const double g = s.attraction_G * G_scale;
    const int n = count();
    for (int i = 0; i < n; ++i) {
      const point<D> xi = x.template segment<D>(D * i);
      const double mi = s.moving_mass[static_cast<std::size_t>(i)];
      for (int j = i + 1; j < n; ++j) {
        const point<D> d = x.template segment<D>(D * j) - xi;
        const double r2 = d.squaredNorm(), r = std::sqrt(r2);
        const point<D> fij = (g * mi * s.moving_mass[static_cast<std::size_t>(j)] / (r2 * r)) * d;
        f.template segment<D>(D * i) += fij;
        f.template segment<D>(D * j) -= fij;
      }
      for (std::size_t k = 0; k < s.fixed_mass.size(); ++k) {
        if (s.fixed_mass[k] == 0.0) continue;
        const point<D> d = fixed_point<D>(s, static_cast<int>(k)) - xi;
        const double r2 = d.squaredNorm(), r = std::sqrt(r2);
        f.template segment<D>(D * i) += (g * mi * s.fixed_mass[k] / (r2 * r)) * d;
      }
    }
  }

  // Adds the blocks of one two-ended element to da/dx (or da/dv): with A = dF_a/d(x_b - x_a),
  // end a gets -A (from x_a), +A (x_b); end b the opposite; each row scaled by 1 / m.
  template <int D>
  void add_pair(jacobian_matrix& j, int a, int b, const Eigen::Matrix<double, D, D>& blk) const {
    const auto& im = data->inverse_mass;
    for (int r = 0; r < D; ++r)
      for (int c = 0; c < D; ++c) {
        if (a >= 0) {
          const double sa = im[static_cast<std::size_t>(a)] * blk(r, c);
          j(D * a + r, D * a + c) -= sa;
          if (b >= 0) j(D * a + r, D * b + c) += sa;
        }
        if (b >= 0) {
          const double sb = im[static_cast<std::size_t>(b)] * blk(r, c);
          j(D * b + r, D * b + c) -= sb;
          if (a >= 0) j(D * b + r, D * a + c) += sb;
        }
      }
  }

  template <int D>
  void jacobian_in(const vec& x, const vec& v, jacobian_matrix& dadx, jacobian_matrix& dadv) const {
    using mat = Eigen::Matrix<double, D, D>;
    const scene_data& s = *data;
    dadx.set_zero();
    dadv.set_zero();
    // A spring (problems/spring_chain.hpp's derivation): with l = |d|, u = d / l,
    // P = I - u u^T, w the relative velocity:
    //   df/dd = k [(1 - L0/l) I + (L0/l) u u^T] + (c / l) [u w^T P + (w . u) P],  df/dw = c u u^T.
    // On a line P = 0 and u u^T = 1: the blocks are k and c, wherever the ends are.
    for (const auto& sp : s.springs) {
      const double k = sp.stiffness * stiffness_scale, c = sp.damping * damping_scale, l0 = sp.rest_length;
      if constexpr (D == 1) {
        add_pair<D>(dadx, sp.a, sp.b, mat::Constant(k));
        add_pair<D>(dadv, sp.a, sp.b, mat::Constant(c));
        continue;
      }
      const point<D> d = end_x<D>(s, x, sp.b) - end_x<D>(s, x, sp.a);
      const point<D> w = end_v<D>(v, sp.b) - end_v<D>(v, sp.a);
      const double len = d.norm();
      if (!(len > 0.0)) continue;  // coincident ends: no axis
      const point<D> u = d / len;
      const mat uu = u * u.transpose();
      const mat p = mat::Identity() - uu;
      const mat a = k * ((1.0 - l0 / len) * mat::Identity() + (l0 / len) * uu) +
                    (c / len) * (u * (w.transpose() * p) + w.dot(u) * p);
      add_pair<D>(dadx, sp.a, sp.b, a);
      add_pair<D>(dadv, sp.a, sp.b, mat(c * uu));
    }
    if (s.has_drag) {  // d/dv of -(lin + quad |v|) v = -(lin + quad |v|) I - quad v v^T / |v|
      const double lin = s.drag_linear * drag_scale, quad = s.drag_quadratic * drag_scale;
      for (int i = 0; i < count(); ++i) {
        const point<D> vi = v.template segment<D>(D * i);
        const double speed = vi.norm();
        mat blk = (lin + quad * speed) * mat::Identity();
        if (speed > 0.0) blk += (quad / speed) * (vi * vi.transpose());
        const double im = s.inverse_mass[static_cast<std::size_t>(i)];
        for (int r = 0; r < D; ++r)
          for (int c = 0; c < D; ++c) dadv(D * i + r, D * i + c) -= im * blk(r, c);
      }
    }
    if (s.has_attraction) {  // F_i = G m_i m_j d / r^3: dF_i/dd = G m_i m_j (I / r^3 - 3 d d^T / r^5)
      const double g = s.attraction_G * G_scale;
      const auto block = [&](const point<D>& d, double mm) {
        const double r2 = d.squaredNorm(), r = std::sqrt(r2), r3 = r2 * r;
        return mat(g * mm * (mat::Identity() / r3 - (3.0 / (r3 * r2)) * (d * d.transpose())));
      };
      for (int i = 0; i < count(); ++i) {
        const double mi = s.moving_mass[static_cast<std::size_t>(i)];
        for (int j = i + 1; j < count(); ++j)
          add_pair<D>(dadx, i, j,
                      block(x.template segment<D>(D * j) - x.template segment<D>(D * i),
                            mi * s.moving_mass[static_cast<std::size_t>(j)]));
        for (std::size_t k = 0; k < s.fixed_mass.size(); ++k)
          if (s.fixed_mass[k] != 0.0)
            add_pair<D>(
                dadx, i, ~static_cast<int>(k),
                block(fixed_point<D>(s, static_cast<int>(k)) - x.template segment<D>(D * i), mi * s.fixed_mass[k]));
      }
    }
  }

  template <int D>
  double energy_in(const vec& x, const vec& v) const {
    const scene_data& s = *data;
    double e = 0.0;
    for (int i = 0; i < count(); ++i) {
      const double m = s.moving_mass[static_cast<std::size_t>(i)];
      e += 0.5 * m * v.template segment<D>(D * i).squaredNorm();
      for (int c = 0; c < D; ++c) e -= m * gravity_scale * s.gravity[c] * x[D * i + c];
    }
    for (const auto& sp : s.springs) {
      const double stretch = (end_x<D>(s, x, sp.b) - end_x<D>(s, x, sp.a)).norm() - sp.rest_length;
      e += 0.5 * sp.stiffness * stiffness_scale * stretch * stretch;
    }
    if (s.has_attraction) {
      const double g = s.attraction_G * G_scale;
      for (int i = 0; i < count(); ++i) {
        const point<D> xi = x.template segment<D>(D * i);
        const double mi = s.moving_mass[static_cast<std::size_t>(i)];
        for (int j = i + 1; j < count(); ++j)
          e -= g * mi * s.moving_mass[static_cast<std::size_t>(j)] / (x.template segment<D>(D * j) - xi).norm();
        for (std::size_t k = 0; k < s.fixed_mass.size(); ++k)
          if (s.fixed_mass[k] != 0.0)
            e -= g * mi * s.fixed_mass[k] / (fixed_point<D>(s, static_cast<int>(k)) - xi).norm();
      }
    }
    return e;
  }
};

// A scene with walls ([[plane]]): the scene's forces, and its masses' contacts with the
// planes resolved as problems/bouncing_ball.hpp resolves the ball's with the ground, at
// the end of each step (core/drive.hpp's end_of_step): a mass found on a plane's wrong
// side, n . x < offset, is moved back onto it along n, and if it approaches, its velocity
// v_n = (v . n) n, v_t = v - v_n becomes v_t' - k_r v_n (the lecture's response).
//
// v_t' is Coulomb's law applied to the contact's impulse, as impulse-based engines do
// (Box2D's contact solver clamps the tangent impulse to mu times the normal impulse):
// the normal impulse per unit mass is j = (1 + k_r) |v_n|; the slip stops if |v_t| <=
// mu_s j (static friction holds), else it loses mu_k j of its speed (kinetic). The
// lecture's k_f then takes its share: v_t' = (1 - k_f) v_t''. On a mass resting on the
// plane (k_r = 0), the step's normal impulse is what the force pressed into the plane
// over dt, so the slip slows by mu_k |F_n| dt / m a step: Coulomb's sliding friction,
// F = mu_k |F_n|, and the block sticks where tan(theta) <= mu_s, as the lecture's incline
// (tests/test_scenes.cpp checks both). The references locate the contacts (CVODE's root
// finding on contact_gap). A type of its own: the methods that run on problems with
// contacts are another set (no peers, no Verner pairs).
struct contact_scene : scene {
  using scene::scene;
  contact_scene defaults() const { return contact_scene(data); }

  // The smallest signed distance of a moving mass to a plane.
  double contact_gap(double, const vec& x, const vec&) const {
    const int d = data->dim;
    double gap = std::numeric_limits<double>::infinity();
    for (int i = 0; i < count(); ++i)
      for (const auto& p : data->planes) gap = std::min(gap, distance(p, x, d * i, d));
    return gap;
  }
  contact_outcome resolve_contacts(double, vec& x, vec& v) const {
    const int d = data->dim;
    contact_outcome c;
    for (int i = 0; i < count(); ++i)
      for (const auto& p : data->planes) {
        const double g = distance(p, x, d * i, d);
        double vn = 0.0;
        for (int k = 0; k < d; ++k) vn += p.normal[static_cast<std::size_t>(k)] * v[d * i + k];
        if (g > 0.0 || (g == 0.0 && vn >= 0.0)) continue;
        c.depth = std::max(c.depth, -g);
        c.changed = c.changed || g < 0.0;
        for (int k = 0; k < d; ++k) x[d * i + k] -= g * p.normal[static_cast<std::size_t>(k)];  // onto the plane
        if (vn < 0.0) {        // approaching: v_b = v_t' - k_r v_n
          double slip2 = 0.0;  // |v_t|^2
          for (int k = 0; k < d; ++k) {
            const double t = v[d * i + k] - vn * p.normal[static_cast<std::size_t>(k)];
            slip2 += t * t;
          }
          const double impulse = -(1.0 + p.restitution) * vn, slip = std::sqrt(slip2);
          double keep = 1.0 - p.tangential_loss;  // v_t' = keep v_t
          if (p.friction != 0.0 || p.static_friction != 0.0)
            keep *= slip <= p.static_friction * impulse ? 0.0 : std::max(0.0, 1.0 - p.friction * impulse / slip);
          for (int k = 0; k < d; ++k) {
            const double nk = p.normal[static_cast<std::size_t>(k)];
            v[d * i + k] = keep * (v[d * i + k] - vn * nk) - p.restitution * vn * nk;
          }
          ++c.resolved;
          c.changed = true;
        }
      }
    return c;
  }
  bool locate_contacts() const { return false; }

 private:
  static double distance(const scene_data::plane& p, const vec& x, int at, int d) {
    double s = 0.0;
    for (int k = 0; k < d; ++k) s += p.normal[static_cast<std::size_t>(k)] * x[at + k];
    return s - p.offset;
  }
};

}  // namespace stepbench

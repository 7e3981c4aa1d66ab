#pragma once
// The lecture's closing example program, bouncing balls: N balls in a box under gravity,
// bouncing off the four walls and off each other with the lecture's collision response
// (on collisions), resolved at the end of each step as a game does (`end_of_step`):
// - wall with inward normal n: a ball whose centre is nearer than r is moved back to
//   distance r, and if it approaches, v_b = (1 - k_f) v_t - k_r v_n;
// - two balls nearer than 2 r: each is moved back half the overlap along the line of
//   centres n, and if they approach (relative velocity u, u.n < 0), the relative
//   velocity becomes (1 - k_f) u_t - k_r u_n, the change split equally between the two
//   equal masses (momentum kept; k_r = 1, k_f = 0 exchanges the normal components).
// Pairs are resolved first, in one pass (each pair once, in the grid's order, seeing the
// velocities the pairs before it left), then the walls, so no ball ends a step outside
// the box. The state is (x_i, z_i) per ball, interleaved, in an Eigen::VectorXd; the
// force is gravity alone.
//
// Broad phase: a uniform grid, rebuilt each pass by a counting sort of the balls by cell
// (O(N), no pair loop over all balls): cells at least 4 r wide (so only balls in the same
// or adjacent cells can touch, and the gap below is continuous) and about as large as the
// box's area per ball; each ball is tested against its own cell and four neighbours (the
// half stencil: every pair once). The grid's arrays are members sized once per scene
// (when the problem is made or its ball count changes), so no step allocates.
//
// Scene: the event-driven truth's default_ball_scene (tests/default_ball_scene.hpp)
// with the box scaled to keep its density: W = 2 s, H = s metres, s = sqrt(max(N, 16) / 16),
// balls of r = 0.05 m on a jittered grid with velocities uniform in [-2, 2) m/s from
// std::mt19937_64(seed); for N = 16 (the default) exactly default_ball_scene(16, seed).
// k_r = 1, k_f = 0 by default: the energy is then conserved and its drift measures the
// contact handling.
//
// Truth: the exact event-driven simulation (at most 64 balls). Horizon 0.25 s, chosen from
// the measured separation growth (event_driven_balls.hpp's notes; seed 1): a difference
// of 1e-12 m in one ball's start has grown 86-fold by 0.25 s (14 ball-ball contacts),
// 1.1e5-fold by 0.5 s and to the box's size by 2 s. A run's error at its first contacts is
// of order v dt (end_of_step: 1e-5 m at the finest level of the ladder): at 0.25 s it
// is still amplified by only about 100, so position errors measure the method and the
// contact handling, not chaos (tests/test_contacts.cpp checks the growth at the
// horizon). Also measured: contacts missed or added against the truth's count, tunnelling
// (a contact found deeper than r: a centre past a wall, or within r of another centre),
// and the energy.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/band_matrix.hpp"
#include "core/concepts.hpp"
#include "problems/exact/event_driven_balls.hpp"

namespace stepbench {

struct bouncing_balls {
  static constexpr std::string_view name = "bouncing_balls";
  static constexpr std::string_view description = "N balls in a box under gravity, walls and each other; end_of_step";
  static constexpr std::string_view position_unit = "m";
  static constexpr bool force_depends_on_velocity = false;
  using vec = Eigen::VectorXd;
  using jacobian_matrix = band_matrix;
  static constexpr int max_truth_balls = 64;

  double balls = 16;
  double seed = 1;
  double radius = 0.05;
  double restitution = 1.0;
  double friction = 0.0;
  double gravity = 9.8;
  double mass_kg = 1.0;
  double duration = 0.25;

  bouncing_balls() { ensure_workspace(); }

  static constexpr auto parameters() {
    using p = param<bouncing_balls>;
    return std::array{
        p{"balls", &bouncing_balls::balls, "1", "number of balls (the truth covers up to 64)", whole_from(1, 1e7)},
        p{"seed", &bouncing_balls::seed, "1", "seed of the initial scene (std::mt19937_64)", whole_from(0, 0x1p53)},
        p{"radius", &bouncing_balls::radius, "m", "radius of every ball", positive},
        p{"restitution", &bouncing_balls::restitution, "1", "k_r: 1 elastic, 0 sticks", in_closed(0.0, 1.0)},
        p{"friction", &bouncing_balls::friction, "1", "k_f: 1 stops the tangential motion, 0 none",
          in_closed(0.0, 1.0)},
        p{"gravity", &bouncing_balls::gravity, "m/s^2", "gravitational acceleration, along -z", non_negative},
        p{"mass_kg", &bouncing_balls::mass_kg, "kg", "mass of every ball", positive},
        p{"duration", &bouncing_balls::duration, "s", "default horizon", positive},
    };
  }
  // What no single parameter's constraint says: the balls fit the scene's grid.
  std::string scene_check() const {
    const double cols = std::ceil(std::sqrt(2.0 * balls));
    if (!(std::min(width() / cols, height() / std::ceil(balls / cols)) > 2.0 * radius))
      return "radius too large: the balls do not fit the scene's grid";
    return {};
  }

  int count() const { return static_cast<int>(balls); }
  int dim() const { return 2 * count(); }
  int body_dim() const { return 2; }  // (x, y) a ball: errors are the worst ball's
  double mass() const { return mass_kg; }
  double horizon() const { return duration; }
  double scale() const { return std::sqrt(std::max(balls, 16.0) / 16.0); }
  double width() const { return 2.0 * scale(); }
  double height() const { return scale(); }

  // place_on_grid's construction, in the scaled box (see above).
  phase<vec> initial() const {
    ensure_workspace();
    const auto s = scene();
    return {interleaved(s.x0), interleaved(s.v0)};
  }

  void force(double, const vec&, const vec&, vec& f) const {
    const double weight = -mass_kg * gravity;
    for (Eigen::Index i = 0; i < f.size(); i += 2) f[i] = 0.0, f[i + 1] = weight;
  }
  // Gravity: dF/dx = dF/dv = 0, a band matrix with no off-diagonals.
  jacobian_matrix make_jacobian() const { return band_matrix(dim(), 0, 0); }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx.set_zero();
    dfdv.set_zero();
  }
  double energy(const vec& x, const vec& v) const {
    double e = 0.5 * v.squaredNorm();
    for (Eigen::Index i = 1; i < x.size(); i += 2) e += gravity * x[i];
    return mass_kg * e;
  }

  // The scene as the event-driven truth takes it.
  exact::ball_scene scene() const {
    exact::ball_scene s;
    s.n = count();
    s.radius = radius;
    s.width = width();
    s.height = height();
    s.gravity = gravity;
    s.restitution = restitution;
    s.friction = friction;
    s.mass = mass_kg;
    exact::place_on_grid(s, static_cast<std::uint64_t>(seed));
    return s;
  }
  exact::event_driven_balls truth() const {
    if (count() > max_truth_balls)
      throw std::invalid_argument("bouncing_balls: the event-driven truth covers at most " +
                                  std::to_string(max_truth_balls) + " balls (set balls <= 64 to measure errors)");
    return exact::event_driven_balls(scene());
  }
  phase<vec> exact(double t) const {
    auto sim = truth();
    sim.advance_to(t);
    return {interleaved(sim.positions()), interleaved(sim.velocities())};
  }
  // The number of exact contacts (walls and pairs) up to t_end; with many balls their
  // order is not comparable contact by contact, so no times or positions.
  exact_contact_list exact_contacts(double t_end) const {
    auto sim = truth();
    sim.advance_to(t_end);
    exact_contact_list out;
    out.count = static_cast<long>(sim.events().size());
    return out;
  }

  // The smallest signed distance: walls, and pairs in the same or adjacent cells (pairs
  // farther apart are at least a cell, 4 r, apart: the gap is capped at cell - 2 r, which
  // keeps it continuous as pairs enter and leave the stencil).
  double contact_gap(double, const vec& x, const vec&) const {
    ensure_workspace();
    const double r = radius, w = width(), h = height();
    double gap = std::min(cell_w_, cell_h_) - 2.0 * r;
    for (int i = 0; i < count(); ++i) {
      const double xi = x[2 * i], zi = x[2 * i + 1];
      gap = std::min({gap, xi - r, w - r - xi, zi - r, h - r - zi});
    }
    for_each_near_pair(
        x, [&](int i, int j) { gap = std::min(gap, (x.segment<2>(2 * j) - x.segment<2>(2 * i)).norm() - 2.0 * r); });
    return gap;
  }

  contact_outcome resolve_contacts(double, vec& x, vec& v) const {
    ensure_workspace();
    contact_outcome c;
    const double r = radius, kr = restitution, kf = friction, reach = 2.0 * r;
    for_each_near_pair(x, [&](int i, int j) {
      const Eigen::Vector2d d = x.segment<2>(2 * j) - x.segment<2>(2 * i);
      const double dist2 = d.squaredNorm();
      if (dist2 == 0.0) return;  // no line of centres
      // The same test as contact_gap's (|d| - 2 r <= 0), touching included, as the walls'
      // is: a root finder (CVODE's) lands on a gap of exactly 0, and a contact left
      // unresolved there is a pair passing through each other, after which the one gap
      // function stays negative and no later contact of any pair is seen.
      const double dist = std::sqrt(dist2), depth = reach - dist;
      if (depth < 0.0) return;  // apart
      const Eigen::Vector2d n = d / dist;
      const Eigen::Vector2d u = v.segment<2>(2 * j) - v.segment<2>(2 * i);
      const double un = u.dot(n);
      if (depth == 0.0 && un >= 0.0) return;  // touching, not approaching
      note_depth(c, depth);
      x.segment<2>(2 * i) -= (0.5 * depth) * n;
      x.segment<2>(2 * j) += (0.5 * depth) * n;
      c.changed = c.changed || depth > 0.0;
      if (un < 0.0) {
        // u' = (1 - k_f) u_t - k_r u_n: the change du = -k_f u_t - (1 + k_r) u_n, half each.
        const Eigen::Vector2d du = -kf * (u - un * n) - ((1.0 + kr) * un) * n;
        v.segment<2>(2 * i) -= 0.5 * du;
        v.segment<2>(2 * j) += 0.5 * du;
        ++c.resolved;
        c.changed = true;
      }
    });
    const double w = width(), h = height();
    for (int i = 0; i < count(); ++i) {
      // axis 0: x (walls left, right), axis 1: z (floor, ceiling); the other axis is tangential.
      for (int axis = 0; axis < 2; ++axis) {
        double& p = x[2 * i + axis];
        double& vn = v[2 * i + axis];
        double& vt = v[2 * i + 1 - axis];
        const double hi = (axis == 0 ? w : h) - r;
        if (p < r || (p == r && vn < 0.0)) {
          note_depth(c, r - p);
          c.changed = c.changed || p < r;
          p = r;
          if (vn < 0.0) vn = -kr * vn, vt *= 1.0 - kf, ++c.resolved, c.changed = true;
        } else if (p > hi || (p == hi && vn > 0.0)) {
          note_depth(c, p - hi);
          c.changed = c.changed || p > hi;
          p = hi;
          if (vn > 0.0) vn = -kr * vn, vt *= 1.0 - kf, ++c.resolved, c.changed = true;
        }
      }
    }
    return c;
  }
  bool locate_contacts() const { return false; }

 private:
  // Per-ball (x, z) pairs as the state's interleaved coordinates.
  static vec interleaved(const std::vector<exact::vec2>& balls) {
    vec out(2 * static_cast<Eigen::Index>(balls.size()));
    for (std::size_t i = 0; i < balls.size(); ++i) out.segment<2>(2 * static_cast<Eigen::Index>(i)) = balls[i];
    return out;
  }
  void note_depth(contact_outcome& c, double depth) const {
    c.depth = std::max(c.depth, depth);
    if (depth > radius) ++c.tunnelled;
  }

  // The grid for the present box, radius and ball count: sized here, and only here.
  void ensure_workspace() const {
    const double w = width(), h = height();
    const double target = std::max(4.0 * radius, std::sqrt(w * h / std::max(balls, 1.0)));
    const int nx = std::max(1, static_cast<int>(std::floor(w / target)));
    const int ny = std::max(1, static_cast<int>(std::floor(h / target)));
    const auto n = static_cast<std::size_t>(std::max(count(), 0));
    if (nx == nx_ && ny == ny_ && order_.size() == n) return;
    nx_ = nx, ny_ = ny;
    cell_w_ = w / nx, cell_h_ = h / ny;
    const auto cells = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
    cell_start_.assign(cells + 1, 0);
    cursor_.assign(cells, 0);
    cell_of_.assign(n, 0);
    order_.assign(n, 0);
  }

  int cell_index(double p, double size, int cells) const {
    const double c = std::floor(p / size);
    return c < 0.0 ? 0 : c >= cells ? cells - 1 : static_cast<int>(c);  // a ball outside the box: the edge cell
  }

  // Counting sort of the balls by cell: order_[cell_start_[c] .. cell_start_[c + 1]) are
  // the balls in cell c.
  void build_grid(const vec& x) const {
    std::fill(cell_start_.begin(), cell_start_.end(), 0);
    const int n = count();
    for (int i = 0; i < n; ++i) {
      const int c = cell_index(x[2 * i + 1], cell_h_, ny_) * nx_ + cell_index(x[2 * i], cell_w_, nx_);
      cell_of_[static_cast<std::size_t>(i)] = c;
      ++cell_start_[static_cast<std::size_t>(c) + 1];
    }
    for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
    std::copy(cell_start_.begin(), cell_start_.end() - 1, cursor_.begin());
    for (int i = 0; i < n; ++i)
      order_[static_cast<std::size_t>(cursor_[static_cast<std::size_t>(cell_of_[static_cast<std::size_t>(i)])]++)] = i;
  }

  // f(i, j) for every pair of balls at x in the same or adjacent cells, each pair once (a
  // cell with itself, then with its neighbours right, below-left... as the half stencil
  // (+1, 0), (-1, +1), (0, +1), (+1, +1)).
  template <class F>
  void for_each_near_pair(const vec& x, F&& f) const {
    build_grid(x);
    constexpr int stencil[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
    for (int cy = 0; cy < ny_; ++cy)
      for (int cx = 0; cx < nx_; ++cx) {
        const auto c = static_cast<std::size_t>(cy * nx_ + cx);
        const int begin = cell_start_[c], end = cell_start_[c + 1];
        if (begin == end) continue;
        for (int a = begin; a < end; ++a)
          for (int b = a + 1; b < end; ++b) f(order_[static_cast<std::size_t>(a)], order_[static_cast<std::size_t>(b)]);
        for (const auto& s : stencil) {
          const int ox = cx + s[0], oy = cy + s[1];
          if (ox < 0 || ox >= nx_ || oy >= ny_) continue;
          const auto o = static_cast<std::size_t>(oy * nx_ + ox);
          for (int a = begin; a < end; ++a)
            for (int b = cell_start_[o]; b < cell_start_[o + 1]; ++b)
              f(order_[static_cast<std::size_t>(a)], order_[static_cast<std::size_t>(b)]);
        }
      }
  }

  // Grid workspace (mutable: sized once per scene, refilled by each pass).
  mutable int nx_ = 0, ny_ = 0;
  mutable double cell_w_ = 1.0, cell_h_ = 1.0;
  mutable std::vector<int> cell_start_, cursor_, cell_of_, order_;
};

}  // namespace stepbench

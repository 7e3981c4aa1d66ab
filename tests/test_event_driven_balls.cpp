// The exact event-driven truth for many bouncing balls (problems/exact/event_driven_balls.hpp):
// closed-form contact times, the lecture's collision response, conservation,
// containment, determinism, the Zeno guard, and the chaos that limits comparisons.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <tuple>
#include <vector>

#include "default_ball_scene.hpp"
#include "problems/exact/event_driven_balls.hpp"

namespace stepbench::exact {

namespace {

ball_scene one_ball(vec2 x, vec2 v, double g = 9.8, double kr = 1.0, double kf = 0.0) {
  ball_scene s;
  s.n = 1;
  s.radius = 0.05;
  s.width = 2.0;
  s.height = 2.0;
  s.gravity = g;
  s.restitution = kr;
  s.friction = kf;
  s.x0 = {x};
  s.v0 = {v};
  return s;
}

ball_scene two_balls(vec2 x0, vec2 v0, vec2 x1, vec2 v1, double kr, double kf) {
  ball_scene s = one_ball(x0, v0, 0.0, kr, kf);
  s.n = 2;
  s.x0.push_back(x1);
  s.v0.push_back(v1);
  return s;
}

// Containment and overlap at the current state, to 1e-9 r.
void expect_inside_and_apart(const event_driven_balls& sim) {
  const ball_scene& s = sim.scene();
  const double r = s.radius, tol = 1e-9 * r;
  const auto& x = sim.positions();
  for (int i = 0; i < s.n; ++i) {
    ASSERT_GE(x[i].x(), r - tol) << "ball " << i << " at t=" << sim.time();
    ASSERT_LE(x[i].x(), s.width - r + tol) << "ball " << i << " at t=" << sim.time();
    ASSERT_GE(x[i].y(), r - tol) << "ball " << i << " at t=" << sim.time();
    ASSERT_LE(x[i].y(), s.height - r + tol) << "ball " << i << " at t=" << sim.time();
    for (int j = i + 1; j < s.n; ++j)
      ASSERT_GE((x[j] - x[i]).norm(), 2.0 * r - tol) << "balls " << i << ", " << j << " at t=" << sim.time();
  }
}

int count(const event_driven_balls& sim, contact_kind k) {
  int c = 0;
  for (const auto& e : sim.events()) c += e.kind == k;
  return c;
}

// Kinetic plus potential energy, sum m |v|^2 / 2 + m g z, at sim.time().
double energy(const event_driven_balls& sim) {
  const ball_scene& s = sim.scene();
  double e = 0.0;
  for (int i = 0; i < s.n; ++i) e += 0.5 * sim.velocities()[i].squaredNorm() + s.gravity * sim.positions()[i].y();
  return s.mass * e;
}

vec2 momentum(const event_driven_balls& sim) {
  vec2 p = vec2::Zero();
  for (const vec2& v : sim.velocities()) p += v;
  return sim.scene().mass * p;
}

int resting_count(const event_driven_balls& sim) {
  int c = 0;
  for (int i = 0; i < sim.size(); ++i) c += sim.resting(i);
  return c;
}

double max_separation(const event_driven_balls& a, const event_driven_balls& b) {
  double m = 0.0;
  for (int i = 0; i < a.size(); ++i) m = std::max(m, (a.positions()[i] - b.positions()[i]).norm());
  return m;
}

}  // namespace

// A ball dropped from rest at height h (centre) meets the floor when its centre reaches
// z = r: t1 = sqrt(2 (h - r) / g), at speed g t1; elastic, it returns to h at 2 t1 and
// lands again at 3 t1. Between contacts the state is the parabola itself.
TEST(event_driven_balls, single_drop_bounces_at_closed_form_time) {
  const double h = 1.5, r = 0.05, g = 9.8;
  event_driven_balls sim(one_ball({1.0, h}, {0.0, 0.0}));
  const double t1 = std::sqrt(2.0 * (h - r) / g);

  sim.advance_to(0.5 * t1);
  EXPECT_NEAR(sim.positions()[0].y(), h - 0.5 * g * 0.25 * t1 * t1, 1e-15);
  EXPECT_NEAR(sim.velocities()[0].y(), -0.5 * g * t1, 1e-15);
  EXPECT_TRUE(sim.events().empty());

  ASSERT_TRUE(sim.next_event(10.0));
  const contact_event& e = sim.events().back();
  EXPECT_EQ(e.kind, contact_kind::floor);
  EXPECT_EQ(e.i, 0);
  EXPECT_EQ(e.j, -1);
  EXPECT_NEAR(e.time, t1, 1e-15);
  EXPECT_NEAR(e.normal_speed, g * t1, 1e-13);
  EXPECT_DOUBLE_EQ(e.point.x(), 1.0);
  EXPECT_DOUBLE_EQ(e.point.y(), 0.0);
  EXPECT_DOUBLE_EQ(sim.positions()[0].y(), r);
  EXPECT_NEAR(sim.velocities()[0].y(), g * t1, 1e-13);
  EXPECT_FALSE(e.came_to_rest);

  sim.advance_to(2.0 * t1);
  EXPECT_NEAR(sim.positions()[0].y(), h, 1e-13);
  EXPECT_NEAR(sim.velocities()[0].y(), 0.0, 1e-13);
  ASSERT_TRUE(sim.next_event(10.0));
  EXPECT_EQ(sim.events().back().kind, contact_kind::floor);
  EXPECT_NEAR(sim.events().back().time, 3.0 * t1, 1e-14);
}

// With k_r < 1 the bounce speeds are v1, k_r v1, k_r^2 v1, ...; the Zeno guard ends the
// sequence at the first bounce whose height (k_r^k v1)^2 / (2 g) is below rest_height.
// Bounce k (k = 0 the first) happens at t1 + sum_{m=1..k} 2 k_r^m v1 / g.
TEST(event_driven_balls, single_ball_comes_to_rest_after_predicted_bounces) {
  const double h = 1.5, r = 0.05, g = 9.8, kr = 0.5;
  ball_scene s = one_ball({1.0, h}, {0.0, 0.0}, g, kr);
  event_driven_balls sim(s);
  const double t1 = std::sqrt(2.0 * (h - r) / g), v1 = g * t1;
  int k = 0;
  double t_k = t1, w = kr * v1;
  while (w * w >= 2.0 * g * s.rest_height) {
    t_k += 2.0 * w / g;
    w *= kr;
    ++k;
  }
  sim.advance_to(10.0);
  ASSERT_EQ(static_cast<int>(sim.events().size()), k + 1);
  EXPECT_EQ(count(sim, contact_kind::floor), k + 1);
  EXPECT_TRUE(sim.events().back().came_to_rest);
  EXPECT_NEAR(sim.events().back().time, t_k, 1e-12);
  // The limit of the infinite sequence differs by less than 2 w / (g (1 - k_r)).
  const double t_inf = t1 + 2.0 * kr * v1 / (g * (1.0 - kr));
  EXPECT_LT(std::abs(sim.events().back().time - t_inf), 2.0 * std::sqrt(2.0 * g * s.rest_height) / (g * (1 - kr)));
  EXPECT_TRUE(sim.resting(0));
  EXPECT_EQ(sim.positions()[0].y(), r);
  EXPECT_EQ(sim.velocities()[0].y(), 0.0);
  EXPECT_EQ(sim.next_event_time(), std::numeric_limits<double>::infinity());
}

// Resting with k_f = 0 keeps the sliding speed (floor bounces do not change v_x); with
// k_f > 0 the limit of (1 - k_f)^n stops it.
TEST(event_driven_balls, resting_ball_slides_without_friction_and_stops_with_it) {
  {
    event_driven_balls sim(one_ball({1.0, 0.5}, {0.1, 0.0}, 9.8, 0.5, 0.0));
    sim.advance_to(3.0);
    EXPECT_TRUE(sim.resting(0));
    EXPECT_EQ(sim.velocities()[0].x(), 0.1);
    EXPECT_NEAR(sim.positions()[0].x(), 1.3, 1e-14);
  }
  {
    event_driven_balls sim(one_ball({1.0, 0.5}, {0.1, 0.0}, 9.8, 0.5, 0.2));
    sim.advance_to(3.0);
    EXPECT_TRUE(sim.resting(0));
    EXPECT_EQ(sim.velocities()[0].x(), 0.0);
    const double x_rest = sim.positions()[0].x();
    sim.advance_to(5.0);
    EXPECT_EQ(sim.positions()[0].x(), x_rest);
  }
}

// The wall rule, v_b = (1 - k_f) v_t - k_r v_n, at the computed time on every wall.
TEST(event_driven_balls, wall_response_is_the_lecture_rule) {
  const double kr = 0.5, kf = 0.25, r = 0.05;
  // Left wall, no gravity: gap (0.5 - r) at 2 m/s.
  event_driven_balls left(one_ball({0.5, 1.0}, {-2.0, 0.3}, 0.0, kr, kf));
  ASSERT_TRUE(left.next_event(10.0));
  EXPECT_EQ(left.events().back().kind, contact_kind::left_wall);
  EXPECT_NEAR(left.events().back().time, (0.5 - r) / 2.0, 1e-15);
  EXPECT_EQ(left.positions()[0].x(), r);
  EXPECT_DOUBLE_EQ(left.velocities()[0].x(), kr * 2.0);
  EXPECT_DOUBLE_EQ(left.velocities()[0].y(), (1 - kf) * 0.3);
  // Right wall, then the ceiling with gravity: z + v_z t - g t^2 / 2 = H - r.
  event_driven_balls right(one_ball({1.5, 1.0}, {1.0, 0.0}, 0.0, kr, kf));
  ASSERT_TRUE(right.next_event(10.0));
  EXPECT_EQ(right.events().back().kind, contact_kind::right_wall);
  EXPECT_NEAR(right.events().back().time, 0.5 - r, 1e-15);
  EXPECT_DOUBLE_EQ(right.velocities()[0].x(), -kr);
  const double g = 9.8, vz = 6.0, gap = 2.0 - r - 1.0;
  event_driven_balls up(one_ball({1.0, 1.0}, {0.4, vz}, g, kr, kf));
  ASSERT_TRUE(up.next_event(10.0));
  EXPECT_EQ(up.events().back().kind, contact_kind::ceiling);
  const double t_c = (vz - std::sqrt(vz * vz - 2 * g * gap)) / g;
  EXPECT_NEAR(up.events().back().time, t_c, 1e-14);
  EXPECT_EQ(up.positions()[0].y(), 2.0 - r);
  EXPECT_NEAR(up.velocities()[0].y(), -kr * (vz - g * t_c), 1e-13);
  EXPECT_DOUBLE_EQ(up.velocities()[0].x(), (1 - kf) * 0.4);
}

// Head-on along x without gravity: contact after gap / closing speed, then the elastic
// exchange of velocities (equal masses).
TEST(event_driven_balls, head_on_elastic_balls_exchange_velocities) {
  const double r = 0.05;
  event_driven_balls sim(two_balls({0.3, 1.0}, {1.0, 0.0}, {0.7, 1.0}, {-0.5, 0.0}, 1.0, 0.0));
  const double gap = 0.4 - 2 * r, closing = 1.5;
  ASSERT_TRUE(sim.next_event(10.0));
  const contact_event& e = sim.events().back();
  EXPECT_EQ(e.kind, contact_kind::ball);
  EXPECT_EQ(e.i, 0);
  EXPECT_EQ(e.j, 1);
  EXPECT_NEAR(e.time, gap / closing, 1e-15);
  EXPECT_NEAR(e.normal_speed, closing, 1e-15);
  EXPECT_NEAR(e.point.x(), 0.3 + gap / closing + r, 1e-15);  // midpoint of the centres
  EXPECT_DOUBLE_EQ(sim.velocities()[0].x(), -0.5);
  EXPECT_DOUBLE_EQ(sim.velocities()[1].x(), 1.0);
  EXPECT_EQ(sim.velocities()[0].y(), 0.0);
  EXPECT_EQ(sim.velocities()[1].y(), 0.0);
  EXPECT_NEAR((sim.positions()[1] - sim.positions()[0]).norm(), 2 * r, 1e-15);
}

// An oblique contact with k_r = 0.5, k_f = 0.3 at a known normal (30 degrees): the
// relative normal velocity is reversed and scaled by k_r, the relative tangential one
// scaled by (1 - k_f), momentum kept.
TEST(event_driven_balls, oblique_ball_response_is_the_lecture_rule) {
  const double r = 0.05, th = std::numbers::pi / 6, kr = 0.5, kf = 0.3, gap = 0.2;
  const vec2 n{std::cos(th), std::sin(th)};
  const vec2 x1{1.0, 1.0}, x0 = x1 - 2 * r * n - vec2{gap, 0.0};
  event_driven_balls sim(two_balls(x0, {1.0, 0.0}, x1, {0.0, 0.0}, kr, kf));
  ASSERT_TRUE(sim.next_event(10.0));
  EXPECT_NEAR(sim.events().back().time, gap, 1e-15);
  const vec2 u_before{-1.0, 0.0}, t_dir{-n.y(), n.x()};
  const vec2 u_after = sim.velocities()[1] - sim.velocities()[0];
  EXPECT_NEAR(u_after.dot(n), -kr * u_before.dot(n), 1e-15);
  EXPECT_NEAR(u_after.dot(t_dir), (1 - kf) * u_before.dot(t_dir), 1e-15);
  const vec2 p = sim.velocities()[0] + sim.velocities()[1];
  EXPECT_NEAR(p.x(), 1.0, 1e-15);
  EXPECT_NEAR(p.y(), 0.0, 1e-15);
}

// A ball falling on a ball resting on the floor: relative motion under g, the quartic
// path. Offset dx, the contact is at height r + sqrt(4 r^2 - dx^2).
TEST(event_driven_balls, ball_dropped_on_resting_ball_hits_at_closed_form_time) {
  const double r = 0.05, g = 9.8, dx = 0.03, h = 0.8;
  ball_scene s = two_balls({1.0, r}, {0.0, 0.0}, {1.0 + dx, h}, {0.0, 0.0}, 1.0, 0.0);
  s.gravity = g;
  event_driven_balls sim(s);
  ASSERT_TRUE(sim.resting(0));
  ASSERT_TRUE(sim.next_event(10.0));
  const contact_event e = sim.events().back();
  EXPECT_EQ(e.kind, contact_kind::ball);
  const double z_contact = r + std::sqrt(4 * r * r - dx * dx);
  EXPECT_NEAR(e.time, std::sqrt(2 * (h - z_contact) / g), 1e-14);
  EXPECT_NEAR((sim.positions()[1] - sim.positions()[0]).norm(), 2 * r, 1e-14);
  // The resting ball is pushed down and sideways: it leaves rest and meets the floor at
  // once, the next event.
  EXPECT_FALSE(sim.resting(0));
  ASSERT_TRUE(sim.next_event(10.0));
  EXPECT_EQ(sim.events().back().kind, contact_kind::floor);
  EXPECT_EQ(sim.events().back().time, e.time);
}

// Elastic, frictionless: kinetic + m g z is conserved over many contacts.
TEST(event_driven_balls, elastic_energy_conserved_over_many_collisions) {
  event_driven_balls sim(default_ball_scene(16, 1));
  const double e0 = energy(sim);
  double worst = 0.0;
  while (sim.next_event(2.0)) worst = std::max(worst, std::abs(energy(sim) - e0) / e0);
  sim.advance_to(2.0);
  worst = std::max(worst, std::abs(energy(sim) - e0) / e0);
  EXPECT_GT(count(sim, contact_kind::ball), 40);
  EXPECT_GT(sim.events().size(), 100u);
  EXPECT_LT(worst, 1e-12);
  std::printf("[ energy   ] N=16, 2 s: %zu events (%d ball-ball), worst relative energy error %.2e\n",
              sim.events().size(), count(sim, contact_kind::ball), worst);
}

// Ball-ball contacts keep the momentum (walls do not; gravity changes only v_z, so the
// x momentum is constant between events). Elastic under gravity, and lossy with friction
// without gravity (with gravity a lossy N = 16 scene collapses within a second, below).
TEST(event_driven_balls, momentum_along_x_conserved_in_ball_contacts) {
  for (const auto& [kr, kf, g] : {std::tuple{1.0, 0.0, 9.8}, std::tuple{0.8, 0.3, 0.0}}) {
    ball_scene s = default_ball_scene(16, 3);
    s.restitution = kr;
    s.friction = kf;
    s.gravity = g;
    event_driven_balls sim(s);
    int checked = 0;
    double px = momentum(sim).x();
    while (sim.next_event(2.0)) {
      const double p_after = momentum(sim).x();
      if (sim.events().back().kind == contact_kind::ball) {
        EXPECT_NEAR(p_after, px, 1e-14) << "k_r=" << kr << " event " << sim.events().size();
        ++checked;
      }
      px = p_after;
    }
    EXPECT_GT(checked, 20) << "k_r=" << kr;
  }
}

// No ball leaves the box or overlaps another by more than 1e-9 r at any event, and the
// event times never decrease: elastic (N = 16 and 64) and lossy with friction.
TEST(event_driven_balls, stays_in_box_without_overlap_and_time_ordered) {
  struct run {
    int n;
    std::uint64_t seed;
    double kr, kf, g, horizon;
  };
  for (const run& c : {run{16, 1, 1.0, 0.0, 9.8, 4.0}, run{64, 2, 1.0, 0.0, 9.8, 1.0}, run{8, 9, 0.9, 0.1, 9.8, 10.0},
                       run{16, 7, 0.8, 0.3, 0.0, 4.0}}) {
    ball_scene s = default_ball_scene(c.n, c.seed);
    s.restitution = c.kr;
    s.friction = c.kf;
    s.gravity = c.g;
    event_driven_balls sim(s);
    double t_prev = 0.0;
    while (sim.next_event(c.horizon)) {
      ASSERT_GE(sim.events().back().time, t_prev);
      t_prev = sim.events().back().time;
      expect_inside_and_apart(sim);
      if (HasFatalFailure()) return;
    }
    EXPECT_GT(count(sim, contact_kind::ball), 20) << "n=" << c.n;
  }
}

// The same seed gives the same scene and the same trajectory bit for bit, whether the
// state is sampled once or every 10 ms (the event search never starts from a sampling
// time); another seed gives another scene.
TEST(event_driven_balls, seeded_scene_reproduces_bit_for_bit) {
  const ball_scene a = default_ball_scene(16, 42), b = default_ball_scene(16, 42), c = default_ball_scene(16, 43);
  ASSERT_TRUE(a.validate().empty());
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(a.x0[i], b.x0[i]);
    EXPECT_EQ(a.v0[i], b.v0[i]);
  }
  EXPECT_NE(a.x0[0], c.x0[0]);
  // The documented distribution: the first draws of mt19937_64(42) through unit_draw.
  std::mt19937_64 rng(42);
  const double cw = 2.0 / 6, ch = 1.0 / 3;
  const double jx = 0.5 * (0.5 * cw - 0.05), jz = 0.5 * (0.5 * ch - 0.05);
  const double x = 0.5 * cw + jx * (2 * unit_draw(rng) - 1), z = 0.5 * ch + jz * (2 * unit_draw(rng) - 1);
  const double vx = 2.0 * (2 * unit_draw(rng) - 1);
  EXPECT_EQ(a.x0[0], vec2(x, z));
  EXPECT_EQ(a.v0[0].x(), vx);

  event_driven_balls once(a), sampled(b);
  once.advance_to(2.0);
  for (int k = 1; k <= 200; ++k) sampled.advance_to(0.01 * k);
  ASSERT_EQ(once.events().size(), sampled.events().size());
  for (std::size_t k = 0; k < once.events().size(); ++k) {
    EXPECT_EQ(once.events()[k].time, sampled.events()[k].time);
    EXPECT_EQ(once.events()[k].i, sampled.events()[k].i);
    EXPECT_EQ(once.events()[k].j, sampled.events()[k].j);
  }
  sampled.advance_to(2.0);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(once.positions()[i], sampled.positions()[i]);
    EXPECT_EQ(once.velocities()[i], sampled.velocities()[i]);
  }
}

TEST(event_driven_balls, invalid_scenes_are_refused) {
  ball_scene s = default_ball_scene(4, 1);
  s.x0[1] = s.x0[0] + vec2{0.09, 0.0};
  EXPECT_THROW(event_driven_balls{s}, std::invalid_argument);
  s = default_ball_scene(4, 1);
  s.x0[2].y() = 0.01;
  EXPECT_THROW(event_driven_balls{s}, std::invalid_argument);
  s = default_ball_scene(4, 1);
  s.restitution = 1.5;
  EXPECT_THROW(event_driven_balls{s}, std::invalid_argument);
  EXPECT_THROW(default_ball_scene(172, 1), std::invalid_argument);
  EXPECT_NO_THROW(default_ball_scene(171, 1));
  event_driven_balls sim(default_ball_scene(4, 1));
  sim.advance_to(0.5);
  EXPECT_THROW(sim.advance_to(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(sim.advance_to(std::nan("")), std::invalid_argument);
}

// k_r = 0.5: every ball ends resting on the floor (z = r, v_z = 0), and stays there.
// Four balls (seeds 1, 5, 10: 7, 9 and 7 ball-ball contacts before all rest, more while
// they slide); with more balls one usually lands on another and stays on it, which ends
// the truth (next test).
TEST(event_driven_balls, inelastic_balls_come_to_rest_on_the_floor) {
  for (std::uint64_t seed : {1u, 5u, 10u}) {
    ball_scene s = default_ball_scene(4, seed);
    s.restitution = 0.5;
    event_driven_balls sim(s);
    double t_all = -1.0;
    for (int k = 1; k <= 300; ++k) {
      sim.advance_to(0.1 * k);
      if (resting_count(sim) == 4) {
        t_all = sim.time();
        break;
      }
    }
    ASSERT_GT(t_all, 0.0) << "seed " << seed << ": " << resting_count(sim) << " of 4 resting at t=" << sim.time();
    const int ball_contacts_at_rest = count(sim, contact_kind::ball);
    EXPECT_GE(ball_contacts_at_rest, 5);
    const std::size_t events_at_rest = sim.events().size();
    sim.advance_to(t_all + 10.0);
    EXPECT_EQ(resting_count(sim), 4);
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(sim.positions()[i].y(), s.radius);
      EXPECT_EQ(sim.velocities()[i].y(), 0.0);
    }
    expect_inside_and_apart(sim);
    std::printf(
        "[ rest     ] N=4 seed %d: all resting by t=%.1f s after %zu events (%d ball-ball), %zu more in 10 s "
        "of sliding\n",
        static_cast<int>(seed), t_all, events_at_rest, ball_contacts_at_rest, sim.events().size() - events_at_rest);
  }
}

// A ball landing on a resting ball and staying on it is a sustained contact: no
// event-driven truth exists past it. It is reported with its time (the limit of any
// comparison), the state stays the exact one up to it, and later calls throw again.
TEST(event_driven_balls, inelastic_collapse_is_reported_with_its_time) {
  ball_scene s = default_ball_scene(16, 1);
  s.restitution = 0.5;
  event_driven_balls sim(s);
  try {
    while (sim.next_event(5.0)) expect_inside_and_apart(sim);
    FAIL() << "no collapse";
  } catch (const inelastic_collapse& e) {
    EXPECT_NEAR(e.time, 0.5071, 1e-4);
    EXPECT_EQ(e.i, 6);  // wedged between the left wall and ball 0, which slides under it
    EXPECT_EQ(e.j, 0);
    EXPECT_EQ(sim.collapse_time(), e.time);
    EXPECT_EQ(sim.last_event_time(), e.time);
  }
  EXPECT_NO_THROW(sim.advance_to(sim.collapse_time()));
  expect_inside_and_apart(sim);
  EXPECT_THROW(sim.advance_to(1.0), inelastic_collapse);
  EXPECT_EQ(sim.time(), sim.collapse_time());
  EXPECT_THROW(sim.next_event(1.0), inelastic_collapse);
}

// Measured, not asserted: the cost of the truth for the default scene.
TEST(performance, sixteen_balls_two_seconds) {
  const ball_scene s = default_ball_scene(16, 1);
  const int reps = 20;
  std::size_t events = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < reps; ++k) {
    event_driven_balls sim(s);
    sim.advance_to(2.0);
    events = sim.events().size();
  }
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / reps;
  std::printf("[ timing   ] N=16, 2 s simulated: %zu events in %.3f ms (%.2f us per event)\n", events, 1e3 * sec,
              1e6 * sec / static_cast<double>(events));
  ball_scene s64 = default_ball_scene(64, 1);
  const auto start64 = std::chrono::steady_clock::now();
  event_driven_balls sim64(s64);
  sim64.advance_to(2.0);
  const double sec64 = std::chrono::duration<double>(std::chrono::steady_clock::now() - start64).count();
  std::printf("[ timing   ] N=64, 2 s simulated: %zu events in %.3f ms\n", sim64.events().size(), 1e3 * sec64);
}

// Measured, not asserted: how a 1e-12 m difference in one initial position grows with
// the number of ball-ball contacts and with time (the numbers quoted in the header).
// Separation: the largest distance between a ball's two copies. Growth fitted (least
// squares on ln sep) while 1e-11 < sep < 1e-3, before the copies' contact sequences part.
// Also from 1-ulp differences (every coordinate of every ball moved to the next double):
// the truth's own rounding grows the same way, which bounds how long a double-precision
// truth stays exact.
TEST(chaos, separation_growth) {
  auto slope = [](const std::vector<std::pair<double, double>>& pts) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(pts.size());
    for (auto [x, y] : pts) sx += x, sy += y, sxx += x * x, sxy += x * y;
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
  };
  struct crossing {
    double t = -1;
    int contacts = -1;
  };
  // Runs two scenes side by side; returns the first sample time (and ball-ball count)
  // at which their separation exceeds each threshold.
  auto diverge = [&](const ball_scene& s, const ball_scene& p, std::array<double, 3> thresholds, bool print,
                     std::vector<std::pair<double, double>>* by_contact,
                     std::vector<std::pair<double, double>>* by_time) {
    event_driven_balls a(s), b(p);
    std::array<crossing, 3> out{};
    for (int k = 1; k <= 100; ++k) {
      const double t = 0.025 * k;
      a.advance_to(t);
      b.advance_to(t);
      const double sep = max_separation(a, b);
      const int bb = count(a, contact_kind::ball);
      if (print && (k % 10 == 0 || t <= 0.3))
        std::printf("[ chaos    ]       %6.3f  %6zu  %9d  %.3e\n", t, a.events().size(), bb, sep);
      if (by_contact && sep > 1e-11 && sep < 1e-3) {
        by_contact->emplace_back(bb, std::log(sep));
        by_time->emplace_back(t, std::log(sep));
      }
      for (int m = 0; m < 3; ++m)
        if (out[m].t < 0 && sep > thresholds[m]) out[m] = {t, bb};
    }
    return out;
  };
  double sum_lambda = 0, sum_growth = 0;
  int runs = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const ball_scene s = default_ball_scene(16, seed);
    if (seed == 1) std::printf("[ chaos    ] seed 1, dx = 1e-12 m:  t [s]  events  ball-ball  max|dx| [m]\n");
    std::vector<std::pair<double, double>> by_contact, by_time;
    ball_scene p12 = s, pu = s;
    p12.x0[0].x() += 1e-12;
    for (vec2& x : pu.x0) x = {std::nextafter(x.x(), 10.0), std::nextafter(x.y(), 10.0)};
    const auto c12 = diverge(s, p12, {1e-9, 1e-6, 1e-3}, seed == 1, &by_contact, &by_time);
    const auto cu = diverge(s, pu, {1e-9, 1e-6, 1e-3}, false, nullptr, nullptr);
    if (by_contact.size() < 3) continue;
    const double growth = std::exp(slope(by_contact)), lambda = slope(by_time);
    std::printf(
        "[ chaos    ] seed %d: growth %.2f per ball-ball contact, lambda %.1f /s; from 1e-12: sep > 1e-9, "
        "1e-6, 1e-3 at t = %.3f, %.3f, %.3f s (%d, %d, %d contacts); from 1 ulp: at t = %.3f, %.3f, %.3f s\n",
        static_cast<int>(seed), growth, lambda, c12[0].t, c12[1].t, c12[2].t, c12[0].contacts, c12[1].contacts,
        c12[2].contacts, cu[0].t, cu[1].t, cu[2].t);
    sum_lambda += lambda;
    sum_growth += growth;
    ++runs;
  }
  ASSERT_GT(runs, 0);
  std::printf("[ chaos    ] mean over %d seeds: growth %.2f per ball-ball contact, lambda %.1f /s (x10 every %.3f s)\n",
              runs, sum_growth / runs, sum_lambda / runs, std::log(10.0) / (sum_lambda / runs));
}

}  // namespace stepbench::exact

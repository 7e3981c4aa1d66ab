// Contacts in the drive loop (core/drive.hpp): the contact times and counts a run records
// in both modes, against the exact bounce sequence; the bouncing-ball reference (CVODE
// with root finding) against the same; the bouncing balls' broad phase against an O(N^2)
// check, their scene against the event-driven truth's, and the horizon's chaos bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/drive.hpp"
#include "core/measure.hpp"
#include "default_ball_scene.hpp"
#include "integrators/all.hpp"
#include "parts/study.hpp"
#include "problems/bouncing_ball.hpp"
#include "problems/bouncing_balls.hpp"
#include "registry/registry.hpp"
#include "run/sweep.hpp"
#include "run_fixed.hpp"

using namespace stepbench;

namespace {

bouncing_ball ball() { return bouncing_ball{}; }
bouncing_ball located_ball() { return bouncing_ball_locate(); }

using test_support::run_fixed;

}  // namespace

// end_of_step: every contact is recorded at the end of the step in which the ball went
// through the plane, one per exact contact, never early. The first is within a step of
// the exact time; each bounce then starts up to a step late and with the speed gained in
// that step, so the k-th contact (from 0) is late by less than 2 (k + 1) dt (measured at
// dt = 0.01: 0.0154 s and 0.037 s for the second and third).
TEST(contacts, end_of_step_records_the_step_end_after_each_contact) {
  const auto p = ball();
  const auto exact = p.exact_contacts(p.horizon());
  ASSERT_EQ(exact.count, 3);  // t = 0.452, 1.175, 1.753 s
  for (double dt : {1e-2, 1e-3, 1e-4}) {
    const auto r = run_fixed(p, velocity_verlet{}, dt);
    ASSERT_EQ(r.contacts, exact.count) << dt;
    ASSERT_EQ(r.contact_times.size(), exact.times.size());
    for (std::size_t k = 0; k < exact.times.size(); ++k) {
      EXPECT_GE(r.contact_times[k], exact.times[k] - 1e-12) << dt << " contact " << k;
      const double late = k == 0 ? dt * (1 + 1e-9) : 2.0 * static_cast<double>(k + 1) * dt;
      EXPECT_LT(r.contact_times[k], exact.times[k] + late) << dt << " contact " << k;
      // On a grid point (the step's end).
      EXPECT_NEAR(r.contact_times[k] / dt, std::round(r.contact_times[k] / dt), 1e-6) << dt;
      EXPECT_EQ(r.contact_x(1, static_cast<Eigen::Index>(k)), 0.0);  // put back on the plane
    }
  }
}

// locate: velocity Verlet is exact on the parabola, so the located contact times are the
// exact ones to the root finder's tolerance (1e-12 of a step), at every dt.
TEST(contacts, locate_finds_the_exact_contact_times) {
  const auto p = located_ball();
  const auto exact = p.exact_contacts(p.horizon());
  for (double dt : {0.1, 1e-2, 1e-3}) {
    const auto r = run_fixed(p, velocity_verlet{}, dt);
    ASSERT_EQ(r.contacts, exact.count) << dt;
    for (std::size_t k = 0; k < exact.times.size(); ++k) {
      EXPECT_NEAR(r.contact_times[k], exact.times[k], 1e-10) << dt << " contact " << k;
      EXPECT_NEAR(r.contact_x(0, static_cast<Eigen::Index>(k)), exact.positions[k][0], 1e-9) << dt;
    }
    // And the whole motion with it.
    const auto truth = p.exact(p.horizon());
    EXPECT_LT((r.final_state.x - truth.x).norm(), 1e-9) << dt;
    EXPECT_LT((r.final_state.v - truth.v).norm(), 1e-9) << dt;
  }
  // An adaptive method locates on its dense output.
  const auto times = sample_times(p.horizon(), 4);
  const auto r = drive_adaptive(p, rk45(1e-10), p.horizon(), times, 1L << 20);
  ASSERT_EQ(r.contacts, exact.count);
  for (std::size_t k = 0; k < exact.times.size(); ++k) EXPECT_NEAR(r.contact_times[k], exact.times[k], 1e-9);
}

// The record keeps the first 64 contacts and counts them all; a Zeno sequence (the ball
// coming to rest) neither hangs the loop nor loses the count.
TEST(contacts, records_the_first_64_and_counts_all) {
  bouncing_ball p;
  p.restitution = 0.5;
  p.duration = 3.0;  // past the accumulation of contacts at t_inf = 1.36 s
  const auto r = run_fixed(p, semi_implicit_euler{}, 1e-3);
  EXPECT_GT(r.contacts, 64);
  EXPECT_EQ(r.contact_times.size(), 64u);
  EXPECT_TRUE(std::is_sorted(r.contact_times.begin(), r.contact_times.end()));
  EXPECT_NEAR(r.final_state.x.y(), 0.0, 1e-4);  // resting on the plane
  auto q = bouncing_ball_locate();
  q.restitution = 0.5;
  q.duration = 3.0;
  const auto rl = run_fixed(q, rk4{}, 1e-2);
  EXPECT_GT(rl.contacts, 64);
  EXPECT_NEAR(rl.final_state.x.y(), 0.0, 1e-3);
}

// Contacts are counted per contact: several resolved in one pass share the time.
TEST(contacts, several_contacts_in_one_pass) {
  drive_result<Eigen::VectorXd> r;
  r.start(2, 0);
  contact_outcome c;
  c.resolved = 3;
  c.tunnelled = 1;
  c.depth = 0.2;
  r.contact(0.5, c, Eigen::Vector2d(1.0, 2.0));
  EXPECT_EQ(r.contacts, 3);
  EXPECT_EQ(r.tunnelled, 1);
  EXPECT_EQ(r.max_penetration, 0.2);
  ASSERT_EQ(r.contact_times.size(), 3u);
  EXPECT_EQ(r.contact_times[2], 0.5);
  drive_result<Eigen::VectorXd> big;
  big.start(100, 0);
  big.contact(0.5, c, Eigen::VectorXd::Zero(100));
  EXPECT_EQ(big.contact_x.size(), 0);  // positions only for small states
}

// The study's measure: the contact errors, and the order each contact mode achieves.
// end_of_step puts the ball back on the plane up to dt after the contact, and the error
// then falls erratically with the phase of the grid against the contact times (velocity
// Verlet: 0.026 m at three successive dt, then 0.0057 at two): no method does better
// than first order between the first level under 5% of the scale and the finest. locate
// keeps the method's own accuracy: exact on the parabola for order >= 2, first order for
// explicit and semi-implicit Euler.
TEST(contacts, orders_in_both_modes) {
  sweep_options opts;
  opts.problems = {"bouncing_ball", "bouncing_ball_locate"};
  opts.methods = {"euler", "semi_implicit_euler", "velocity_verlet", "rk4", "forest_ruth"};
  opts.parts = {"sweep"};
  const study s = run_sweep(opts);
  for (const auto& ps : s.problems) {
    const bool locate = ps.problem->name() == "bouncing_ball_locate";
    EXPECT_EQ(ps.truth.contact_count, 3);
    for (const auto& ms : ps.methods) {
      const std::string what = std::string(ps.problem->name()) + "/" + ms.info.name;
      const bool euler_like = ms.info.declared_order == 1;
      if (!locate) {
        const method_row* first = nullptr;
        for (const auto& r : ms.rows)
          if (!first && r.metrics.err_pos_max < 0.05 * ps.truth.pos_scale) first = &r;
        ASSERT_NE(first, nullptr) << what;
        const auto& last = ms.rows.back();
        const double slope =
            std::log(first->metrics.err_pos_max / last.metrics.err_pos_max) / std::log(first->param / last.param);
        std::printf("  %-32s end_of_step: slope %.2f from dt %.3g to %.3g\n", what.c_str(), slope, first->param,
                    last.param);
        EXPECT_LE(slope, 1.15) << what;
        EXPECT_GE(slope, 0.5) << what;
      } else if (euler_like) {
        ASSERT_EQ(ms.fit.state, fit_result::status::fitted) << what << ": " << ms.fit.note;
        EXPECT_NEAR(ms.fit.order, 1.0, 0.15) << what;
      } else {
        // Exact up to the root finder: errors at round-off at every level.
        for (const auto& r : ms.rows) EXPECT_LT(r.metrics.err_pos_max, 1e-9) << what << " dt " << r.param;
      }
      for (const auto& r : ms.rows) {
        if (r.param > 0.01) continue;
        EXPECT_EQ(r.metrics.contact_count_err, 0.0) << what << " dt " << r.param;
        // Located by an exact step: to the root finder's tolerance. Otherwise late by less
        // than 2 (k + 1) dt at the k-th contact (end_of_step; see above: up to 6.1 dt
        // measured at the third), and for the Euler methods off with their O(dt)
        // trajectories (explicit Euler: up to 11 dt measured).
        const double bound = locate && !euler_like ? 1e-3 * r.param + 1e-9 : (euler_like ? 15.0 : 8.0) * r.param;
        EXPECT_LE(r.metrics.contact_time_err, bound) << what << " dt " << r.param;
        EXPECT_TRUE(std::isfinite(r.metrics.contact_pos_err));
      }
    }
    // The references: CVODE with root finding agrees with the exact sequence; the others
    // cannot stop at a contact and are recorded as unsupported.
    for (const auto& ref : ps.truth.references) {
      if (ref.source == "cvode_bdf" || ref.source == "cvode_adams") {
        EXPECT_EQ(ref.status, "ok") << ref.source << ": " << ref.reason;
        EXPECT_LT(ref.vs.worst(), 1e-9) << ref.source;
        EXPECT_EQ(ref.solution.contacts, 3) << ref.source;
      } else {
        EXPECT_EQ(ref.status, "unsupported") << ref.source;
      }
    }
  }
}

// Peers (and the baseline) have no contact handling in their loops: they are not run on a
// problem with contacts.
TEST(contacts, only_our_methods_run_on_contact_problems) {
  for (const char* name : {"bouncing_ball", "bouncing_balls", "sliding_block"})
    for (const auto& m : make_problem(name)->methods())
      EXPECT_EQ(m.origin, method_origin::ours) << name << " " << m.name;
  bool peers = false;
  for (const auto& m : make_problem("kepler")->methods()) peers = peers || m.origin == method_origin::peer;
  EXPECT_TRUE(peers);
}

// The balls' scene is the event-driven truth's default scene at 16 balls; larger scenes
// keep its density.
TEST(bouncing_balls, scene_is_the_truths_default) {
  const bouncing_balls p;
  const auto ref = exact::default_ball_scene(16, 1);
  const auto s = p.initial();
  ASSERT_EQ(s.x.size(), 32);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(s.x[2 * i], ref.x0[i].x());
    EXPECT_EQ(s.x[2 * i + 1], ref.x0[i].y());
    EXPECT_EQ(s.v[2 * i], ref.v0[i].x());
    EXPECT_EQ(s.v[2 * i + 1], ref.v0[i].y());
  }
  bouncing_balls big;
  big.balls = 10000;
  EXPECT_EQ(validate(big), "");
  EXPECT_NEAR(big.width() * big.height() / 10000, 2.0 / 16, 1e-12);
  EXPECT_EQ(big.initial().x.size(), 20000);
}

// The grid finds exactly the overlapping pairs an O(N^2) loop finds, and the response
// keeps momentum in ball-ball contacts.
TEST(bouncing_balls, broad_phase_matches_all_pairs) {
  bouncing_balls p;
  p.balls = 400;
  p.radius = 0.12;  // dense: many overlaps
  auto s = p.initial();
  Eigen::VectorXd x = s.x;
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += 0.05 * std::sin(17.0 * static_cast<double>(i));  // shuffle
  int overlapping = 0;
  const int n = p.count();
  double min_gap = 1e300;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double d = (x.segment<2>(2 * j) - x.segment<2>(2 * i)).norm();
      min_gap = std::min(min_gap, d - 2 * p.radius);
      if (d < 2 * p.radius) ++overlapping;
    }
  ASSERT_GT(overlapping, 10);
  // The gap: walls or the closest pair, whichever is smaller.
  double wall = 1e300;
  for (int i = 0; i < n; ++i)
    wall = std::min({wall, x[2 * i] - p.radius, p.width() - p.radius - x[2 * i], x[2 * i + 1] - p.radius,
                     p.height() - p.radius - x[2 * i + 1]});
  EXPECT_DOUBLE_EQ(p.contact_gap(0.0, x, s.v), std::min(wall, min_gap));
  // Resolution: every overlap found by the grid is pushed apart (none deeper than the
  // rounding of the pushes is left among the pairs the pass saw).
  Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  const contact_outcome c = p.resolve_contacts(0.0, x, v);
  EXPECT_TRUE(c.changed);
  EXPECT_GT(c.depth, 0.0);
  // Two balls: the lecture's response, momentum kept, restitution along the normal.
  bouncing_balls two;
  two.balls = 2;
  two.restitution = 0.7;
  two.friction = 0.3;
  Eigen::VectorXd y(4), u(4);
  y << 0.5, 0.5, 0.57, 0.55;  // 0.086 apart: overlapping (2 r = 0.1)
  u << 1.0, 0.2, -0.5, 0.1;
  const Eigen::Vector2d normal = (y.segment<2>(2) - y.segment<2>(0)).normalized();
  const Eigen::Vector2d rel = u.segment<2>(2) - u.segment<2>(0);
  const Eigen::Vector2d p0 = u.segment<2>(0) + u.segment<2>(2);
  const contact_outcome c2 = two.resolve_contacts(0.0, y, u);
  EXPECT_EQ(c2.resolved, 1);
  EXPECT_LT((u.segment<2>(0) + u.segment<2>(2) - p0).norm(), 1e-15);
  const Eigen::Vector2d rel2 = u.segment<2>(2) - u.segment<2>(0);
  EXPECT_NEAR(rel2.dot(normal), -0.7 * rel.dot(normal), 1e-14);
  const Eigen::Vector2d t_before = rel - rel.dot(normal) * normal, t_after = rel2 - rel2.dot(normal) * normal;
  EXPECT_NEAR((t_after - 0.7 * t_before).norm(), 0.0, 1e-14);
  EXPECT_NEAR((y.segment<2>(2) - y.segment<2>(0)).norm(), 0.1, 1e-15);  // moved apart to touching
}

// The horizon (0.25 s) is short enough that chaos does not swamp the comparison: a 1e-9 m
// change in one ball's start grows by well under 10^3 by then (measured ~86 for 1e-12,
// see problems/bouncing_balls.hpp).
TEST(bouncing_balls, horizon_is_before_chaos) {
  const bouncing_balls p;
  auto scene = p.scene();
  exact::event_driven_balls a(scene);
  scene.x0[0].x() += 1e-9;
  exact::event_driven_balls b(scene);
  a.advance_to(p.horizon());
  b.advance_to(p.horizon());
  double worst = 0.0;
  for (int i = 0; i < p.count(); ++i) worst = std::max(worst, (a.positions()[i] - b.positions()[i]).norm());
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(a.events().size(), 20u);  // there are contacts to get right
}

// A fine run of the time-stepped balls is close to the truth, conserves energy to a few
// parts in 10^3 with k_r = 1, tunnels nowhere and gets the contact count right.
TEST(bouncing_balls, fine_run_against_the_truth) {
  const bouncing_balls p;
  const auto r = run_fixed(p, velocity_verlet{}, p.horizon() / 65536);
  const auto truth = p.exact(p.horizon());
  EXPECT_LT((r.final_state.x - truth.x).norm(), 1e-2);
  EXPECT_EQ(r.tunnelled, 0);
  EXPECT_NEAR(static_cast<double>(r.contacts), static_cast<double>(p.exact_contacts(p.horizon()).count), 2.0);
  EXPECT_NEAR(p.energy(r.final_state.x, r.final_state.v) / p.energy(truth.x, truth.v), 1.0, 5e-3);
  // The coarsest level of the ladder: balls overlap deeply but do not leave the box.
  const auto coarse = run_fixed(p, velocity_verlet{}, p.horizon() / 32);
  for (int i = 0; i < p.count(); ++i) {
    EXPECT_GE(coarse.final_state.x[2 * i], p.radius);
    EXPECT_LE(coarse.final_state.x[2 * i], p.width() - p.radius);
  }
}

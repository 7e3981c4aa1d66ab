// XPBD (integrators/xpbd.hpp) against what it must equal, and the N-link pendulum
// (problems/n_pendulum.hpp) against published equations and its own invariants.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "core/drive.hpp"
#include "core/measure.hpp"
#include "integrators/all.hpp"
#include "problems/n_pendulum.hpp"
#include "problems/pendulum.hpp"
#include "problems/spring_chain.hpp"
#include "problems/stiff_spring.hpp"
#include "registry/registry.hpp"
#include "run/challenge.hpp"
#include "study/challenge.hpp"

using namespace stepbench;

namespace {

std::vector<double> frame_times(int frames, double hz) {
  std::vector<double> t;
  for (int i = 1; i <= frames; ++i) t.push_back(i / hz);
  return t;
}

double max_abs_diff(const run_result& a, const run_result& b) {
  double worst = 0.0;
  for (std::size_t j = 0; j < a.sample_y.size(); ++j)
    for (std::size_t i = 0; i < a.sample_y[j].size(); ++i)
      worst = std::max(worst, std::abs(a.sample_y[j][i] - b.sample_y[j][i]));
  return worst;
}

// For one linear constraint one XPBD pass solves the backward Euler equation exactly:
// with a~ = 1 / (k h^2), w = 1 / m, the pass gives x' = x_p - C(x_p) / (1 + a~ / w),
// i.e. x' (1 + k h^2 / m) = x + h v, which is implicit Euler's x' = x + h v',
// v' = v - h k x' / m. With the damper (g = c / (k h)) the pass's equation
// ((1 + g) w + a~) dlambda = -C - g (x_p - x) is implicit Euler's with -c v' too.
void expect_xpbd_equals_implicit_euler(double k_d) {
  auto p = make_problem("stiff_spring");
  p->set("k_d", k_d);
  const double hz = 60.0;
  const auto times = frame_times(32, hz);
  const run_result xpbd_run = p->run("xpbd", 1.0 / hz, p->horizon(), times);
  const run_result ie_run = p->run("implicit_euler", 1.0 / hz, p->horizon(), times);
  ASSERT_TRUE(xpbd_run.stop_reason.empty()) << xpbd_run.stop_reason;
  ASSERT_EQ(xpbd_run.sample_y.size(), times.size());
  // The amplitude is x0 = 0.01 m, and x0 w = 10 m/s: round-off of the view's 1 m rest
  // length (1.1e-16 m a step) over 32 steps bounds the difference.
  EXPECT_LT(max_abs_diff(xpbd_run, ie_run), 1e-13) << "k_d " << k_d;
  // ... and both are backward Euler's first frame from rest: m (x1 - x0) / h^2 =
  // -k x1 - c (x1 - x0) / h, so x1 = x0 (m + c h) / (m + c h + k h^2).
  const double h = 1.0 / hz, m = 1.0, k = 1e6, x0 = 0.01;
  EXPECT_NEAR(xpbd_run.sample_y[0][0], x0 * (m + k_d * h) / (m + k_d * h + k * h * h), 1e-16);
}

}  // namespace

TEST(xpbd, one_substep_on_the_undamped_stiff_spring_is_implicit_euler) { expect_xpbd_equals_implicit_euler(0.0); }

TEST(xpbd, one_substep_on_the_damped_stiff_spring_is_implicit_euler_too) { expect_xpbd_equals_implicit_euler(20.0); }

// A rigid link (compliance 0) stays stable at every substep count: the bob stays on its
// circle and the energy never grows (XPBD's projection only removes energy).
TEST(xpbd, rigid_pendulum_is_stable_at_every_substep_count) {
  pendulum p;
  p.theta0_deg = 179.0;
  const double e0 = p.energy(p.initial().x, p.initial().v);
  for (int substeps : {1, 2, 5, 50, 500}) {
    xpbd_solver s(p.particles(p.initial().x, p.initial().v));
    const double h = 1.0 / 60.0 / substeps;
    for (int i = 0; i < 600 * substeps; ++i) {  // 10 s
      s.step(h, 1);
      ASSERT_NEAR(s.s.x.col(0).norm(), p.length_m, 1e-14) << "substeps " << substeps << " step " << i;
      const double e = 0.5 * p.mass_kg * s.s.v.squaredNorm() + p.mass_kg * p.gravity * (s.s.x(1, 0) + p.length_m);
      ASSERT_LE(e, e0 * (1.0 + 1e-12)) << "substeps " << substeps << " step " << i;
    }
  }
}

// The challenge's 3 links and a 10-link chain, rigid (compliance 0), with one pass a
// substep (xpbd) and with 10 passes a step (xpbd_iterations): at every substep count of
// a 60 Hz frame the energy never rises above its start for 10 s (a projection removes
// the velocity along the links, which only takes energy out), so the motion stays
// bounded. One Gauss-Seidel pass leaves the links stretched, most at one substep (6 % on
// 3 links, 27 % on 10 measured), at least halved from each substep count to the next
// here, and under 1e-4 at 500 (2e-6 and 2e-5 measured).
TEST(xpbd, rigid_n_pendulum_is_stable_at_every_substep_count) {
  for (const int links : {3, 10}) {
    n_pendulum p;
    p.links = links;
    const auto s0 = p.initial();
    const double e0 = p.energy(s0.x, s0.v), scale = p.mass_kg * p.gravity * p.length_m * links * (links + 1) / 2.0;
    for (const int iterations : {1, 10}) {
      double previous_link = 1.0;
      for (const int substeps : {1, 2, 5, 50, 500}) {
        xpbd_solver s(p.particles(s0.x, s0.v));
        const double h = 1.0 / 60.0 / substeps;
        double worst_link = 0.0;
        for (int i = 0; i < 600 * substeps; ++i) {  // 10 s
          s.step(h, iterations);
          double e = 0.0;
          for (int b = 0; b < links; ++b) {
            const Eigen::Vector3d above = b == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(s.s.x.col(b - 1));
            worst_link = std::max(worst_link, std::abs((s.s.x.col(b) - above).norm() / p.length_m - 1.0));
            e += p.mass_kg * (0.5 * s.s.v.col(b).squaredNorm() + p.gravity * s.s.x(1, b));
          }
          ASSERT_LE(e, e0 + 1e-12 * scale)
              << links << " links, " << iterations << " passes, substeps " << substeps << ", step " << i;
        }
        EXPECT_LT(worst_link, 0.5 * previous_link)
            << links << " links, " << iterations << " passes, substeps " << substeps;
        previous_link = worst_link;
      }
      EXPECT_LT(previous_link, 1e-4) << links << " links, " << iterations << " passes, 500 substeps";
    }
  }
}

// First order on the pendulum: halving the substep halves the error (against the closed form).
TEST(xpbd, first_order_on_the_pendulum) {
  auto p = make_problem("pendulum");
  const double horizon = p->horizon();
  const std::vector<double> times{horizon};
  const auto truth = p->exact(horizon);
  double previous = 0.0;
  for (int level = 6; level <= 10; ++level) {
    const double dt = 1.0 / 60.0 / (1 << level);
    const run_result r = p->run("xpbd", dt, horizon, times);
    const double err = std::abs(r.final_y[0] - truth[0]);
    if (level > 6) {
      EXPECT_GT(previous / err, 1.8) << "level " << level;
      EXPECT_LT(previous / err, 2.2) << "level " << level;
    }
    previous = err;
  }
}

// On the chain, the constraint view's springs are the force model's: with many substeps
// XPBD converges to the same motion the references give (first order).
TEST(xpbd, spring_chain_converges_to_the_force_model) {
  spring_chain p;
  p.masses = 8;
  p.k_s = 1e3;
  const double horizon = 0.25;
  const auto exact = drive(p, rk4{}, 1e-5, horizon, std::span<const record_point>{}).final_state;
  double previous = 0.0;
  for (int substeps : {64, 128, 256, 512}) {
    xpbd_solver s(p.particles(p.initial().x, p.initial().v));
    const double h = horizon / substeps;
    for (int i = 0; i < substeps; ++i) s.step(h, 1);
    spring_chain::vec x(p.dim()), v(p.dim());
    p.from_particles(s.s, x, v);
    const double err = (x - exact.x).norm();
    if (previous > 0.0) {
      EXPECT_GT(previous / err, 1.7) << substeps;
      EXPECT_LT(previous / err, 2.3) << substeps;
    }
    previous = err;
  }
  EXPECT_LT(previous, 2e-3);  // 1.3e-3 m at 512 substeps: first order in a stiff chain
}

// One link is the simple pendulum: theta'' = -(g / l) sin theta.
TEST(n_pendulum, one_link_is_the_simple_pendulum) {
  n_pendulum p;
  p.links = 1;
  n_pendulum::vec x(1), v(1), f(1);
  for (double theta : {0.3, 1.2, 2.9}) {
    x << theta;
    v << 1.7;
    p.force(0.0, x, v, f);
    EXPECT_NEAR(f[0], -(p.gravity / p.length_m) * std::sin(theta), 1e-13);
  }
}

// Two links against the double pendulum's equations as published (e.g. Neumann,
// myPhysicsLab "Double Pendulum", and every textbook derivation), with unequal values.
TEST(n_pendulum, two_links_are_the_textbook_double_pendulum) {
  n_pendulum p;
  p.links = 2;
  p.mass_kg = 1.3;
  p.length_m = 0.7;
  p.gravity = 9.81;
  const double m = p.mass_kg, l = p.length_m, g = p.gravity;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), rate(-5.0, 5.0);
  for (int trial = 0; trial < 20; ++trial) {
    n_pendulum::vec x(2), v(2), f(2);
    x << angle(rng), angle(rng);
    v << rate(rng), rate(rng);
    const double t1 = x[0], t2 = x[1], w1 = v[0], w2 = v[1], d = t1 - t2;
    const double den = 2 * m + m - m * std::cos(2 * t1 - 2 * t2);
    const double a1 = (-g * (2 * m + m) * std::sin(t1) - m * g * std::sin(t1 - 2 * t2) -
                       2 * std::sin(d) * m * (w2 * w2 * l + w1 * w1 * l * std::cos(d))) /
                      (l * den);
    const double a2 = 2 * std::sin(d) *
                      (w1 * w1 * l * (m + m) + g * (m + m) * std::cos(t1) + w2 * w2 * l * m * std::cos(d)) / (l * den);
    p.force(0.0, x, v, f);
    EXPECT_NEAR(f[0], a1, 1e-11 * (1 + std::abs(a1)));
    EXPECT_NEAR(f[1], a2, 1e-11 * (1 + std::abs(a2)));
  }
}

// The force conserves the energy it declares: RK4 at a small step holds it to 1e-10 over
// the challenge's chaotic second.
TEST(n_pendulum, the_force_conserves_its_energy) {
  n_pendulum p;
  const auto s0 = p.initial();
  const double e0 = p.energy(s0.x, s0.v);
  const auto end = drive(p, rk4{}, 1e-5, 1.0, std::span<const record_point>{}).final_state;
  const double scale = p.mass_kg * p.gravity * p.length_m * 6;  // |E| of the hanging chain
  EXPECT_LT(std::abs(p.energy(end.x, end.v) - e0), 1e-10 * scale);
  EXPECT_GT((end.x - s0.x).norm(), 0.5);  // it moved
}

// The constraint view and back is the identity, and the bobs are where observe puts them.
TEST(n_pendulum, constraint_view_round_trip) {
  n_pendulum p;
  p.links = 5;
  n_pendulum::vec x(5), v(5), x2(5), v2(5);
  x << 0.1, -2.0, 3.0, 1.0, -0.5;
  v << 1.0, 2.0, -3.0, 0.5, 0.0;
  const particle_system s = p.particles(x, v);
  p.from_particles(s, x2, v2);
  EXPECT_LT((x - x2).norm(), 1e-14);
  EXPECT_LT((v - v2).norm(), 1e-13);
  EXPECT_NEAR(constraint_violation(s), 0.0, 1e-15);
  Eigen::VectorXd pos(10), vel(10);
  p.observe(x, v, pos, vel);
  EXPECT_NEAR(pos[8], s.x(0, 4), 1e-15);
  EXPECT_NEAR(pos[9], s.x(1, 4), 1e-15);
}

// Errors are measured on the bobs (m): the truth's position scale is the chain's reach.
TEST(n_pendulum, errors_are_on_the_bobs_positions) {
  auto p = make_problem("n_pendulum");
  EXPECT_EQ(p->observed_dim(), 6);
  const auto o = p->observed(p->initial());
  ASSERT_EQ(o.size(), 12u);
  EXPECT_NEAR(o[4], 0.9, 1e-15);  // the third bob, at three links' length along +x
  EXPECT_NEAR(o[5], 0.0, 1e-15);
}

// Problems without a constraint view do not run the position-based methods.
TEST(xpbd, runs_only_where_a_constraint_view_is_declared) {
  for (const char* name : {"pendulum", "n_pendulum", "stiff_spring", "spring_chain"}) {
    const auto ms = make_problem(name)->methods();
    EXPECT_TRUE(std::any_of(ms.begin(), ms.end(), [](const method_info& m) { return m.name == "xpbd"; })) << name;
  }
  for (const char* name : {"projectile", "kepler", "bouncing_ball"}) {
    const auto ms = make_problem(name)->methods();
    EXPECT_FALSE(std::any_of(ms.begin(), ms.end(), [](const method_info& m) { return m.name == "xpbd"; })) << name;
  }
}

// The challenge's numbers are the runs they name: each entry's error is a fresh run of
// its method at its steps a frame, measured against the references; one substep of one
// pass and one step of one pass are the same XPBD step.
TEST(challenge, entries_are_the_runs_they_name) {
  challenge_options o;
  o.energy_horizon = 20.0;
  o.small_steps_counts = {1, 4};
  const challenge_result r = run_challenge(o);
  ASSERT_EQ(r.entries.size(), 1 + o.competitors.size());
  EXPECT_EQ(r.entries[0].method, "xpbd");
  EXPECT_EQ(r.entries[0].steps_per_frame, 50);
  EXPECT_LT(r.entries[0].link_err_max, 1e-3);
  EXPECT_GT(r.entries[0].link_err_max, 0.0);  // one Gauss-Seidel pass leaves the links a little off
  EXPECT_DOUBLE_EQ(r.energy_scale, 1.0 * 10.0 * 0.3 * 6.0);
  auto p = make_problem("n_pendulum");
  std::vector<double> frames;
  for (int i = 1; i <= 120; ++i) frames.push_back(i / 60.0);
  const truth_table truth = build_truth(*p, frames, {});
  for (const auto& e : r.entries) {
    const bool adaptive = find_method(e.method).kind == method_kind::adaptive;
    EXPECT_EQ(adaptive, std::isfinite(e.tolerance)) << e.method;
    const double param = adaptive ? e.tolerance : 1.0 / (60.0 * e.steps_per_frame);
    const run_metrics m = measure(*p, p->run(e.method, param, 2.0, frames), truth);
    EXPECT_EQ(m.err_pos_max, e.err_pos_max) << e.method;
    EXPECT_TRUE(e.stable) << e.method << ": " << e.note;
    // An adaptive competitor gets the tightest tolerance whose measured time a frame is
    // at most xpbd's (unless even 1e-1 costs more). (A fixed-step one's count comes from
    // its time at one step a frame, so its own measured time may be a little over.)
    if (adaptive && e.tolerance < 0.05) {
      EXPECT_LE(e.ns_per_frame, r.entries[0].ns_per_frame) << e.method;
    }
  }
  // dop853 (adaptive) is among them, at a decade of tolerance.
  const auto dop = std::find_if(r.entries.begin(), r.entries.end(), [](const auto& e) { return e.method == "dop853"; });
  ASSERT_NE(dop, r.entries.end());
  EXPECT_NEAR(std::log10(dop->tolerance), std::round(std::log10(dop->tolerance)), 1e-12);
  // rk4 at its steps a frame is far more accurate than xpbd at 50 (fourth against first order).
  EXPECT_LT(r.entries[1].err_pos_max, 1e-3 * r.entries[0].err_pos_max);
  ASSERT_EQ(r.verdicts.size(), 3u);
  EXPECT_EQ(r.verdict_criteria, (std::vector<std::string>{"accuracy", "stability", "speed"}));
  EXPECT_NE(r.verdicts[0].find(fmt::format("{:.3g} m", r.entries[0].err_pos_max)), std::string::npos) << r.verdicts[0];
  auto row = [&](const std::string& problem, const std::string& design, int n) {
    for (const auto& s : r.small_steps)
      if (s.problem == problem && s.design == design && s.n == n) return s;
    ADD_FAILURE() << problem << " " << design << " " << n;
    return small_steps_row{};
  };
  for (const char* problem : {"n_pendulum", "spring_chain"}) {
    EXPECT_EQ(row(problem, "xpbd_substeps", 1).err_pos, row(problem, "xpbd_iterations", 1).err_pos) << problem;
    EXPECT_GT(row(problem, "implicit_euler", 1).work_per_frame, 1.0) << problem;  // Newton's evaluations
  }
  // On the stiff rope, explicit substeps diverge where XPBD's do not (w dt = 18.9 at one).
  EXPECT_TRUE(row("spring_chain", "semi_implicit_euler_substeps", 1).diverged);
  EXPECT_FALSE(row("spring_chain", "xpbd_substeps", 1).diverged);
}

// Every run records its constraint violation: xpbd's own links, a force-based method's
// state seen through the view (rigid links in generalized coordinates hold exactly), NaN
// where there is no view.
TEST(xpbd, runs_record_their_constraint_violation) {
  auto p = make_problem("n_pendulum");
  std::vector<double> frames;
  for (int i = 1; i <= 32; ++i) frames.push_back(i / 60.0);
  const truth_table truth = build_truth(*p, frames, {});
  const run_metrics x = measure(*p, p->run("xpbd", 1.0 / 600.0, p->horizon(), frames), truth);
  EXPECT_GT(x.constraint_violation_max, 1e-8);
  EXPECT_LT(x.constraint_violation_max, 1e-2);
  const run_metrics r = measure(*p, p->run("rk4", 1.0 / 600.0, p->horizon(), frames), truth);
  EXPECT_LT(r.constraint_violation_max, 1e-15);
  auto q = make_problem("projectile");
  const std::vector<double> end{q->horizon()};
  const truth_table qt = build_truth(*q, end, {});
  EXPECT_TRUE(std::isnan(measure(*q, q->run("rk4", 0.1, q->horizon(), end), qt).constraint_violation_max));
}

// XPBD is scored on the bobs it draws (its particles, links a little stretched), not on
// the link angles read back from them, which put every bob back on its link's length.
// By hand: the worst bob's distance from the truth's, over the frames.
TEST(xpbd, is_scored_on_the_bobs_it_draws) {
  auto p = make_problem("n_pendulum");
  std::vector<double> frames;
  for (int i = 1; i <= 120; ++i) frames.push_back(i / 60.0);
  const truth_table truth = build_truth(*p, frames, {});
  const run_result run = p->run("xpbd", 1.0 / 120.0, 2.0, frames);  // 2 substeps a 60 Hz frame
  ASSERT_EQ(run.drawn_samples.size(), frames.size());
  ASSERT_EQ(run.drawn_final.size(), 12u);
  double drawn = 0.0, read_back = 0.0, stretch = 0.0;
  for (std::size_t j = 0; j < frames.size(); ++j) {
    const auto exact = p->observed(truth.y[j]), back = p->observed(run.sample_y[j]);
    const auto& bobs = run.drawn_samples[j];
    for (int i = 0; i < 3; ++i) {
      const double dx = bobs[2 * i] - exact[2 * i], dy = bobs[2 * i + 1] - exact[2 * i + 1];
      drawn = std::max(drawn, std::sqrt(dx * dx + dy * dy));
      read_back = std::max(read_back, std::hypot(back[2 * i] - exact[2 * i], back[2 * i + 1] - exact[2 * i + 1]));
    }
    stretch = std::max(stretch, std::abs(std::hypot(bobs[0], bobs[1]) - 0.3));  // the first link
  }
  const run_metrics m = measure(*p, run, truth);
  EXPECT_EQ(m.err_pos_max, drawn);
  EXPECT_GT(stretch, 1e-6);                                      // the particles are not on the links
  EXPECT_GT(std::abs(m.err_pos_max - read_back), 1e-3 * drawn);  // and that is what is scored
  // A method that steps the state draws the state's bobs.
  EXPECT_TRUE(p->run("rk4", 1.0 / 120.0, 2.0, frames).drawn_samples.empty());
}

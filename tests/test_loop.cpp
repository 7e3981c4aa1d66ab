// The game loop around the integrator (core/game_loop.hpp, study/loop.hpp): the fixed
// loop is independent of the display clock to the bit, interpolation never
// extrapolates and blends initialised states, the clamp bounds the steps a frame, the
// variable loop depends on the clock, a seeded jittered clock reproduces bit for bit,
// the cost model finds the spiral of death and the clamp that prevents it, and bad
// input is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>

#include "core/game_loop.hpp"
#include "judge/loop.hpp"
#include "registry/registry.hpp"
#include "run/loop.hpp"
#include "study/loop.hpp"

using namespace stepbench;

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// The clocks every test runs over: constant rates (multiples of the physics rate and
// not), jittered with two seeds, and a stall with the clamp and without it.
std::vector<loop_config> clocks(loop_config base) {
  std::vector<loop_config> out;
  for (double hz : {30.0, 50.0, 60.0, 75.0, 144.0, 165.0, 240.0}) {
    base.display_hz = hz;
    out.push_back(base);
  }
  base.display_hz = 60.0;
  for (std::uint64_t seed : {1u, 2u}) {
    loop_config j = base;
    j.jitter_seed = seed;
    out.push_back(j);
  }
  loop_config st = base;
  st.stall_at_s = 0.4 * base.horizon;
  out.push_back(st);
  st.clamp_s = 0.0;
  out.push_back(st);
  return out;
}

loop_config config(loop_design d, double physics_hz, double horizon) {
  loop_config c;
  c.design = d;
  c.physics_hz = physics_hz;
  c.horizon = horizon;
  return c;
}

}  // namespace

// The accumulator loop steps the same dt from the same states whatever the clock: at
// the same simulated time (N whole steps) the physics state is identical to the bit, on
// every clock, for several horizons (some a whole number of steps, some not), and the
// interpolated loop's is the same state. Its shown state at the horizon differs only by
// the rounding of alpha.
TEST(loop, fixed_loop_is_bit_identical_on_every_clock) {
  for (const char* pname : {"damped_spring", "pendulum"}) {
    const auto problem = make_problem(pname);
    for (const char* method : {"rk4", "semi_implicit_euler", "velocity_verlet"}) {
      for (double physics_hz : {50.0, 60.0, 100.0}) {
        for (double horizon : {2.5, 3.0, problem->horizon()}) {
          const long whole = static_cast<long>(std::floor(horizon * physics_hz * (1.0 + 1e-9)));
          const loop_result first = problem->loop(method, config(loop_design::fixed, physics_hz, horizon));
          const loop_result blend = problem->loop(method, config(loop_design::interpolated, physics_hz, horizon));
          for (loop_design d : {loop_design::fixed, loop_design::interpolated})
            for (const auto& c : clocks(config(d, physics_hz, horizon))) {
              const loop_result r = problem->loop(method, c);
              SCOPED_TRACE(fmt::format("{}/{} {} at {:g} Hz physics, {:g} Hz display, horizon {:g}, clamp {:g}", pname,
                                       method, to_string(d), physics_hz, c.display_hz, horizon, c.clamp_s));
              EXPECT_EQ(r.physics_steps, whole);
              EXPECT_EQ(r.physics_t, static_cast<double>(whole) / physics_hz);
              EXPECT_TRUE(same_bits(r.final_physics, first.final_physics));
              if (d == loop_design::interpolated) {
                for (std::size_t i = 0; i < r.final_shown.size(); ++i)
                  EXPECT_NEAR(r.final_shown[i], blend.final_shown[i],
                              1e-12 * std::max(1.0, std::abs(blend.final_shown[i])));
              }
            }
        }
      }
    }
  }
}

// alpha = accumulator / dt is in [0, 1) after every frame: interpolation never
// extrapolates, on any clock (jittered frames end anywhere inside a step).
TEST(loop, alpha_in_zero_one) {
  const auto problem = make_problem("damped_spring");
  for (double physics_hz : {50.0, 60.0, 100.0, 120.0})
    for (const auto& c : clocks(config(loop_design::interpolated, physics_hz, problem->horizon()))) {
      const loop_result r = problem->loop("rk4", c);
      for (double a : r.alpha) {
        ASSERT_GE(a, 0.0) << c.display_hz;
        ASSERT_LT(a, 1.0) << c.display_hz;
      }
    }
}

// The blend starts from an initialised previous state: before the first step (a
// 240 Hz display over 50 Hz physics shows several frames first) the shown state is the
// initial state itself, shown as the state at t = 0.
TEST(loop, interpolation_blends_initialised_states) {
  const auto problem = make_problem("damped_spring");
  loop_config c = config(loop_design::interpolated, 50.0, 1.0);
  c.display_hz = 240.0;
  const loop_result r = problem->loop("rk4", c);
  const auto y0 = problem->initial();
  ASSERT_EQ(r.steps[0], 0);
  for (std::size_t j = 0; j < r.frames() && r.steps[j] == 0 && j < 4; ++j) {
    EXPECT_EQ(r.shown[j], y0[0]) << j;
    EXPECT_EQ(r.shown_t[j], 0.0) << j;
  }
}

// The interpolated loop shows the past by one physics step, and the fixed loop by the
// accumulator: measured from the states (the least-squares lag), with rk4 (whose own
// error is far below the lag), it agrees with what the clocks say.
TEST(loop, measured_lag) {
  const auto problem = make_problem("damped_spring");
  loop_options opts;
  for (double physics_hz : {50.0, 100.0}) {
    loop_config c = config(loop_design::interpolated, physics_hz, problem->horizon());
    c.display_hz = 144.0;
    const loop_row r = run_loop_config(*problem, "rk4", c, opts);
    EXPECT_NEAR(r.lag_s, 1.0 / physics_hz, 0.01 / physics_hz);
    // (a little under dt: the frames before the first step show the initial state, at t = 0)
    EXPECT_NEAR(r.lag_clock_s, 1.0 / physics_hz, 1e-3 / physics_hz);
    c.design = loop_design::fixed;
    const loop_row f = run_loop_config(*problem, "rk4", c, opts);
    EXPECT_NEAR(f.lag_s, f.lag_clock_s, 0.05 / physics_hz);
    EXPECT_GT(f.lag_clock_s, 0.2 / physics_hz);
    EXPECT_LT(f.lag_clock_s, 0.8 / physics_hz);
    // Interpolation removes the judder of a non-multiple rate, the fixed loop has it.
    EXPECT_LT(r.judder, 0.2 * f.judder);
  }
}

// The clamp bounds the steps of a frame: after the 1 s stall the accumulator loop takes
// at most ceil(clamp / dt) steps in a frame; without the clamp the whole second.
TEST(loop, clamp_bounds_steps_per_frame) {
  const auto problem = make_problem("pendulum");
  for (double physics_hz : {50.0, 60.0, 120.0})
    for (double clamp : {0.05, 0.1, 0.25}) {
      loop_config c = config(loop_design::fixed, physics_hz, problem->horizon());
      c.stall_at_s = 1.0;
      c.clamp_s = clamp;
      const loop_result r = problem->loop("rk4", c);
      int most = 0, clamped = 0;
      for (std::size_t j = 0; j < r.frames(); ++j) most = std::max(most, r.steps[j]), clamped += r.clamped[j];
      EXPECT_LE(most, static_cast<int>(std::ceil(clamp * physics_hz))) << physics_hz << " " << clamp;
      EXPECT_EQ(clamped, 1);
      c.clamp_s = 0.0;
      const loop_result off = problem->loop("rk4", c);
      int burst = 0;
      for (std::size_t j = 0; j < off.frames(); ++j)
        if (off.stall[j]) burst = off.steps[j];
      EXPECT_GE(burst, static_cast<int>(std::floor(physics_hz * (1.0 - 1e-9))));
    }
}

// The variable loop's state at the horizon depends on the clock: each display rate
// takes other steps. The substeps loop likewise, less.
TEST(loop, variable_depends_on_the_clock) {
  const auto problem = make_problem("damped_spring");
  for (loop_design d : {loop_design::variable, loop_design::substeps}) {
    const auto cs = clocks(config(d, 60.0, problem->horizon()));
    const loop_result first = problem->loop("semi_implicit_euler", cs.front());
    int differ = 0;
    for (std::size_t i = 1; i < cs.size(); ++i)
      differ += !same_bits(problem->loop("semi_implicit_euler", cs[i]).final_physics, first.final_physics);
    EXPECT_EQ(differ, static_cast<int>(cs.size()) - 1) << to_string(d);
  }
  loop_config a = config(loop_design::variable, 60.0, problem->horizon()), b = a;
  b.display_hz = 144.0;
  const double xa = problem->loop("semi_implicit_euler", a).final_physics[0];
  const double xb = problem->loop("semi_implicit_euler", b).final_physics[0];
  EXPECT_GT(std::abs(xa - xb), 1e-6);
}

// A seeded jittered clock reproduces bit for bit; another seed gives other frames. The
// frames are the documented distribution: (1 + j (2u - 1)) / rate, u from the top 53
// bits of std::mt19937_64(seed).
TEST(loop, jittered_clock_reproduces) {
  const auto problem = make_problem("pendulum");
  loop_config c = config(loop_design::interpolated, 100.0, problem->horizon());
  c.jitter_seed = 42;
  const loop_result a = problem->loop("rk4", c), b = problem->loop("rk4", c);
  EXPECT_TRUE(same_bits(a.display_t, b.display_t));
  EXPECT_TRUE(same_bits(a.shown, b.shown));
  EXPECT_TRUE(same_bits(a.final_physics, b.final_physics));
  c.jitter_seed = 43;
  EXPECT_FALSE(same_bits(problem->loop("rk4", c).display_t, a.display_t));

  std::mt19937_64 rng(42);
  for (std::size_t j = 0; j + 1 < a.frames() && j < 100; ++j) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
    EXPECT_EQ(a.interval[j], (1.0 + 0.25 * (2.0 * u - 1.0)) / 60.0) << j;  // to the bit
  }
  // The generator is the standard's: its 10000th output from the default seed.
  std::mt19937_64 standard;
  standard.discard(9999);
  EXPECT_EQ(standard(), 9981545732273789042ull);
}

// The cost model: a step that costs more than the simulated time it advances makes the
// accumulator loop spiral without the clamp; the clamp holds it in slow motion. At a
// cost well under dt the loop catches up after the stall. The variable and substeps
// loops take a fixed number of steps a frame and never spiral.
TEST(loop, cost_model_finds_the_spiral_and_the_clamp_that_prevents_it) {
  loop_config c = config(loop_design::fixed, 60.0, 10.0);
  c.stall_at_s = 5.0;
  const double dt_ns = 1e9 / 60.0;
  const loop_cost heavy = cost_verdict(c, 1.5 * dt_ns, "stated");
  EXPECT_EQ(heavy.schedule.outcome, loop_outcome::slow_motion);
  EXPECT_EQ(heavy.without_clamp, loop_outcome::spiral);
  EXPECT_TRUE(heavy.clamp_prevented_spiral);
  EXPECT_GT(heavy.schedule.load, 1.0);
  EXPECT_LE(heavy.schedule.steps_max, static_cast<int>(std::ceil(0.25 * 60.0)) + 1);

  const loop_cost light = cost_verdict(c, 0.5 * dt_ns, "stated");
  EXPECT_EQ(light.schedule.outcome, loop_outcome::keeps_up);
  EXPECT_EQ(light.without_clamp, loop_outcome::keeps_up);
  EXPECT_FALSE(light.clamp_prevented_spiral);
  EXPECT_GT(light.schedule.late_frames, 0);  // the burst after the stall overruns its frame

  const loop_cost cheap = cost_verdict(c, 100.0, "stated");
  EXPECT_EQ(cheap.schedule.outcome, loop_outcome::keeps_up);
  EXPECT_EQ(cheap.schedule.late_frames, 0);
  EXPECT_NEAR(cheap.schedule.worst_work_s, 15 * 100e-9, 1e-15);  // the clamped burst: 0.25 s of 1/60 s steps

  for (loop_design d : {loop_design::variable, loop_design::substeps}) {
    c.design = d;
    EXPECT_NE(cost_verdict(c, 1.5 * dt_ns, "stated").without_clamp, loop_outcome::spiral) << to_string(d);
  }
}

// The study of one pair: every design, clock and physics rate, measured; the fixed and
// interpolated loops independent of the clock; the cheapest design at 60 Hz found.
TEST(loop, study_of_a_pair) {
  const auto problem = make_problem("damped_spring");
  const loop_options opts;
  const loop_method m = run_loop_method(*problem, find_method("rk4"), opts);
  const std::size_t clocks_per_rate = opts.display_hz.size() + 3;
  EXPECT_EQ(m.rows.size(), clocks_per_rate * (1 + 3 * opts.physics_hz.size()));
  for (const auto& r : m.rows) {
    EXPECT_FALSE(r.diverged) << r.note;
    if (uses_accumulator(r.config.design)) {
      EXPECT_EQ(r.physics_clock_dependence, 0.0);
    }
    if (r.config.design == loop_design::interpolated && r.clock == "constant") {
      EXPECT_NEAR(r.lag_s, r.config.dt(), 0.01 * r.config.dt());
    }
    if (r.config.design == loop_design::variable && r.clock == "constant" && r.config.display_hz != 60.0) {
      EXPECT_GT(r.clock_dependence, 0.0);
    }
  }
  bool found = false;
  for (const auto& c : cheapest_designs(m, opts))
    if (c.display_hz == 60.0) {
      found = c.found;
      EXPECT_LE(c.shown_err_max, opts.target);
      EXPECT_EQ(c.steps_per_frame_mean, 1.0);
    }
  EXPECT_TRUE(found);
}

// Bad input is refused with one line: rates <= 0, a clamp below the physics dt, a stall
// longer than the run, a method the loop does not run.
TEST(loop, bad_input) {
  loop_config c = config(loop_design::fixed, 60.0, 10.0);
  EXPECT_EQ(loop_config_error(c), "");
  auto refused = [](loop_config bad, const char* words) {
    const std::string e = loop_config_error(bad);
    EXPECT_NE(e.find(words), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  };
  loop_config b = c;
  b.display_hz = 0.0;
  refused(b, "--display-hz must be > 0");
  b = c, b.physics_hz = -60.0;
  refused(b, "--physics-hz must be > 0");
  b = c, b.clamp_s = 0.01;
  refused(b, "below the physics dt");
  b = c, b.stall_at_s = 9.5;
  refused(b, "longer than the run");
  b = c, b.horizon = 0.5, b.stall_at_s = 0.0;
  refused(b, "longer than the run");
  b = c, b.display_hz = 1e7;
  refused(b, "frames");

  const auto problem = make_problem("pendulum");
  loop_config bad = c;
  bad.clamp_s = 0.001;
  EXPECT_THROW(problem->loop("rk4", bad), std::invalid_argument);
  EXPECT_THROW(problem->loop("rk45", c), std::invalid_argument);
  EXPECT_THROW(problem->loop("gsl_rk4", c), std::invalid_argument);
  EXPECT_THROW(problem->loop("nope", c), std::invalid_argument);
}

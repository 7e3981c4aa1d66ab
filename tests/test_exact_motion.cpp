// The exact solutions in problems/exact/ against what they claim: initial states,
// invariants, the lecture's worked examples and table, and independent numerical
// integrations written here in plain double (RK4, an event-driven bounce loop).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "problems/exact/bouncing_ball.hpp"
#include "problems/exact/falling_drag.hpp"
#include "problems/exact/friction_table.hpp"
#include "problems/exact/kepler.hpp"
#include "problems/exact/sliding_block.hpp"

namespace stepbench::exact {

namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();
constexpr double pi = std::numbers::pi;
using ld = long double;

// Product code only these tests use: the exact motions' input checks (empty when valid),
// the orbit's constants, the drag's right-hand side and the friction table's lookup.
std::string_view invalid_reason(const kepler_orbit& o) {
  if (!(std::isfinite(o.gm) && o.gm > 0.0)) return "gm must be finite and > 0";
  if (!(std::isfinite(o.a) && o.a > 0.0)) return "a must be finite and > 0";
  if (!(o.e >= 0.0 && o.e < 1.0)) return "e must be in [0, 1)";
  return "";
}
std::string_view invalid_reason(const sliding_block& b) {
  if (!(std::isfinite(b.g) && b.g > 0.0)) return "g must be finite and > 0";
  if (!(b.theta >= 0.0 && b.theta <= 1.5707963267948966)) return "theta must be in [0, pi/2]";
  if (!(std::isfinite(b.mu_s) && b.mu_s >= 0.0)) return "mu_s must be finite and >= 0";
  if (!(std::isfinite(b.mu_k) && b.mu_k >= 0.0)) return "mu_k must be finite and >= 0";
  if (!std::isfinite(b.v0)) return "v0 must be finite";
  return "";
}
std::string_view invalid_reason(const bouncing_ball& b) {
  if (!(std::isfinite(b.g) && b.g > 0.0)) return "g must be finite and > 0";
  if (!(std::isfinite(b.h) && b.h > 0.0)) return "h must be finite and > 0";
  if (!(std::isfinite(b.vx0) && std::isfinite(b.vz0))) return "vx0 and vz0 must be finite";
  if (!(b.k_r >= 0.0 && b.k_r <= 1.0)) return "k_r must be in [0, 1]";
  if (!(b.k_f >= 0.0 && b.k_f <= 1.0)) return "k_f must be in [0, 1]";
  return "";
}

double specific_energy(const kepler_orbit& o) { return -o.gm / (2.0 * o.a); }
double angular_momentum(const kepler_orbit& o) { return std::sqrt(o.gm * o.a) * std::sqrt((1.0 - o.e) * (1.0 + o.e)); }

// The ODE's right-hand side, dv/dt = g (1 - v/v_t)(1 + v/v_t) for v >= 0 (factored: no
// cancellation of 1 - v^2/v_t^2 near the terminal speed).
double acceleration_at_speed(const falling_drag& f, double v) {
  const double r = v / f.terminal_speed;
  return f.g * (1.0 - r) * (1.0 + r);
}

// The record named `name`, or nullptr.
const friction_record* find_friction(std::string_view name) {
  for (const auto& r : friction_table)
    if (has_name(r, name)) return &r;
  return nullptr;
}

// Classic RK4 on a fixed-size state: y' = f(t, y).
template <std::size_t N, class F>
std::array<double, N> rk4_step(const F& f, double t, const std::array<double, N>& y, double h) {
  auto axpy = [](const std::array<double, N>& a, double s, const std::array<double, N>& b) {
    std::array<double, N> r;
    for (std::size_t i = 0; i < N; ++i) r[i] = a[i] + s * b[i];
    return r;
  };
  const auto k1 = f(t, y);
  const auto k2 = f(t + h / 2, axpy(y, h / 2, k1));
  const auto k3 = f(t + h / 2, axpy(y, h / 2, k2));
  const auto k4 = f(t + h, axpy(y, h, k3));
  std::array<double, N> r;
  for (std::size_t i = 0; i < N; ++i) r[i] = y[i] + h / 6 * (k1[i] + 2 * (k2[i] + k3[i]) + k4[i]);
  return r;
}

// ---------------------------------------------------------------------------------------
// Kepler

// (1 - e) E + e (E - sin E) - M in long double, E - sin E by its series below 1: the
// residual of Kepler's equation for a double E, to ~1e-19.
ld kepler_residual(double E, double e, double M) {
  const ld x = E;
  ld d;
  if (std::abs(E) < 1.0) {
    ld term = x * x * x / 6, sum = 0;
    for (int k = 1; k < 40; ++k) {
      sum += term;
      term *= -x * x / ((2 * k + 2) * (2 * k + 3));
    }
    d = sum;
  } else {
    d = x - std::sin(x);
  }
  return (1 - ld(e)) * x + ld(e) * d - ld(M);
}

double state_error(const kepler_state& s, const kepler_state& r, const kepler_orbit& o) {
  // Position relative to a, velocity relative to the periapsis speed (the orbit's scales).
  const double vp = o.initial().vy;
  return std::max(
      {std::abs(s.x - r.x) / o.a, std::abs(s.y - r.y) / o.a, std::abs(s.vx - r.vx) / vp, std::abs(s.vy - r.vy) / vp});
}

TEST(kepler, initial_state_matches_detest_start) {
  for (double e : {0.0, 0.1, 0.5, 0.9, 0.99}) {
    const kepler_orbit o{1.0, 1.0, e};
    const auto s0 = o.initial();
    EXPECT_EQ(s0.x, 1.0 - e);
    EXPECT_EQ(s0.y, 0.0);
    EXPECT_EQ(s0.vx, 0.0);
    EXPECT_NEAR(s0.vy, std::sqrt((1 + e) / (1 - e)), 2 * eps * s0.vy);
    const auto s = o.at(0.0);
    EXPECT_NEAR(s.x, s0.x, 2 * eps * s0.x) << e;
    EXPECT_EQ(s.y, 0.0);
    EXPECT_EQ(s.vx, 0.0);
    EXPECT_NEAR(s.vy, s0.vy, 4 * eps * s0.vy) << e;
  }
  EXPECT_EQ(invalid_reason(kepler_orbit{}), "");
  EXPECT_NE(invalid_reason(kepler_orbit{1.0, 1.0, 1.0}), "");
  EXPECT_NE(invalid_reason(kepler_orbit{1.0, -1.0, 0.5}), "");
}

// Period 2 pi sqrt(a^3 / gm), written without a^3; the state returns after whole periods.
TEST(kepler, returns_after_whole_periods) {
  const kepler_orbit earth_leo{3.986004418e14, 7.0e6, 0.3};  // SI units, a^3 ~ 3e20
  EXPECT_NEAR(earth_leo.period(), 2 * pi * std::sqrt(7.0e6 * 7.0e6 * 7.0e6 / 3.986004418e14), 1e-12 * 5800);
  const kepler_orbit huge{1.0, 1e120, 0.5};  // a^3 would overflow
  EXPECT_TRUE(std::isfinite(huge.period()));
  EXPECT_NEAR(huge.period() / 1e180, 2 * pi, 1e-13);
  for (double e : {0.0, 0.5, 0.9, 0.99}) {
    for (const kepler_orbit& o : {kepler_orbit{1.0, 1.0, e}, kepler_orbit{3.986004418e14, 7.0e6, e}}) {
      const auto s0 = o.initial();
      for (double n : {1.0, 3.0, -1.0, 10.0})
        EXPECT_LT(state_error(o.at(n * o.period()), s0, o), 1e-13) << e << " " << n;
    }
  }
}

// Energy and angular momentum computed from the returned state equal the constants.
TEST(kepler, energy_and_angular_momentum_from_state) {
  for (double e : {0.0, 0.3, 0.9, 0.99}) {
    for (const kepler_orbit& o : {kepler_orbit{1.0, 1.0, e}, kepler_orbit{3.986004418e14, 7.0e6, e}}) {
      const double energy = specific_energy(o), l = angular_momentum(o);
      EXPECT_NEAR(energy, -o.gm / (2 * o.a), 1e-15 * std::abs(energy));
      EXPECT_NEAR(l, std::sqrt(o.gm * o.a * (1 - e * e)), 1e-15 * l);
      for (int i = 0; i <= 400; ++i) {
        const double t = o.period() * (i / 200.0 - 0.37);
        const auto s = o.at(t);
        const double r = std::hypot(s.x, s.y);
        const double en = 0.5 * (s.vx * s.vx + s.vy * s.vy) - o.gm / r;
        EXPECT_NEAR(en, energy, 1e-13 * std::abs(energy)) << "e " << e << " t " << t;
        EXPECT_NEAR(s.x * s.vy - s.y * s.vx, l, 1e-13 * l) << "e " << e << " t " << t;
      }
    }
  }
}

// Kepler's equation to round-off: residual below 4 eps (M in [-pi, pi]), and E within
// about an ulp of the root (forward error residual / f'(E) relative to E), in at most
// kepler_max_iterations Halley steps.
TEST(kepler, equation_solved_to_round_off) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-pi, pi), exponent(-300.0, 0.5);
  int max_iterations = 0;
  for (double e : {0.0, 1e-10, 0.01, 0.2, 0.5, 0.8, 0.9, 0.97, 0.99, 0.999, 1 - 1e-6, 1 - 1e-10, 1 - 1e-15}) {
    for (int i = 0; i < 20000; ++i) {
      const double M = i % 2 ? uniform(rng) : std::copysign(std::pow(10.0, exponent(rng)), uniform(rng));
      const auto root = solve_kepler(M, e);
      max_iterations = std::max(max_iterations, root.iterations);
      const double E = root.eccentric_anomaly;
      const ld res = kepler_residual(E, e, std::remainder(M, 2 * pi));
      ASSERT_LT(std::abs(double(res)), 4 * eps) << "e " << e << " M " << M;
      const ld fp = 1 - ld(e) * std::cos(ld(E));
      if (E != 0.0) {
        ASSERT_LT(double(std::abs(res) / fp / std::abs(E)), 1.5 * eps) << "e " << e << " M " << M;
      }
    }
  }
  EXPECT_LE(max_iterations, kepler_max_iterations);
  // Reduction to [-pi, pi] and oddness.
  EXPECT_NEAR(solve_kepler(1.0 + 20 * pi, 0.9).eccentric_anomaly, solve_kepler(1.0, 0.9).eccentric_anomaly, 1e-13);
  EXPECT_EQ(solve_kepler(-0.7, 0.99).eccentric_anomaly, -solve_kepler(0.7, 0.99).eccentric_anomaly);
  // Tiny M at e -> 1: E = M / (1 - e) to round-off (1 - e exact; the double 0.99 is not
  // 99/100), no Danby start far above the root.
  EXPECT_NEAR(solve_kepler(1e-300, 0.99).eccentric_anomaly, 1e-300 / (1 - 0.99), 1e-298 * eps);
  EXPECT_EQ(solve_kepler(0.0, 0.9).eccentric_anomaly, 0.0);
}

TEST(kepler, e_minus_sin_is_relatively_accurate) {
  for (double E : {1e-300, 1e-8, 1e-3, 0.1, 0.5, 0.999, 1.0, 1.5, 1.999, 2.0, 3.0}) {
    const ld x = E;
    ld term = x * x * x / 6, sum = 0;
    for (int k = 1; k < 60; ++k) {
      sum += term;
      term *= -x * x / ((2 * k + 2) * (2 * k + 3));
    }
    EXPECT_NEAR(e_minus_sin(E), double(sum), 3 * eps * double(sum)) << E;
    EXPECT_EQ(e_minus_sin(-E), -e_minus_sin(E));
  }
}

// Largest deviation of fixed-step RK4 on r'' = -gm r / |r|^3 (written above, plain double)
// from the closed form, sampled every eighth of a period over `periods` periods: position
// relative to a, velocity relative to the periapsis speed.
double rk4_kepler_deviation(const kepler_orbit& o, int periods, long steps_per_eighth) {
  const auto rhs = [&](double, const std::array<double, 4>& y) {
    const double r = std::hypot(y[0], y[1]), k = -o.gm / (r * r * r);
    return std::array<double, 4>{y[2], y[3], k * y[0], k * y[1]};
  };
  const auto s0 = o.initial();
  std::array<double, 4> y{s0.x, s0.y, s0.vx, s0.vy};
  const long steps = 8 * periods * steps_per_eighth;
  const double h = periods * o.period() / double(steps);
  double worst = 0.0;
  for (long i = 0; i < steps; ++i) {
    y = rk4_step(rhs, double(i) * h, y, h);
    if ((i + 1) % steps_per_eighth == 0)
      worst = std::max(worst, state_error(kepler_state{y[0], y[1], y[2], y[3]}, o.at(double(i + 1) * h), o));
  }
  return worst;
}

// Against a numerical integration of the ODE over 3 periods at e = 0.9: agreement to 1e-9
// (of a, and of the periapsis speed) at every eighth of a period. Fine steps are needed near
// periapsis (r = 0.1 a, v = 4.4 sqrt(gm / a)): 2^15 per eighth, 786432 in all, where RK4's
// error (about 1e-11) is near its round-off floor. Coarser runs show the error falling at
// fourth order, so the agreement is the integrator converging to the closed form.
TEST(kepler, matches_rk4_integration_over_three_periods) {
  const kepler_orbit o{1.0, 1.0, 0.9};
  const double fine = rk4_kepler_deviation(o, 3, 1L << 15);
  EXPECT_LT(fine, 1e-9);
  char text[32];
  std::snprintf(text, sizeof text, "%.3e", fine);
  RecordProperty("worst_deviation", text);
  const double coarse = rk4_kepler_deviation(o, 1, 1L << 11), half = rk4_kepler_deviation(o, 1, 1L << 12);
  EXPECT_GT(coarse / half, 12.0);
  EXPECT_LT(coarse / half, 20.0);
}

// ---------------------------------------------------------------------------------------
// Falling with quadratic drag

TEST(falling_drag, small_t_is_free_fall) {
  const falling_drag f{9.8, 50.0};
  for (double t : {1e-150, 1e-12, 1e-6, 1e-4, 1e-3, 1e-2}) {
    const auto s = f.at(t);
    const double u = 9.8 * t / 50.0, u2 = u * u;
    // Taylor: 2 ln cosh(u) / u^2 = 1 - u^2/6 + 2u^4/45 - 17u^6/1260, tanh(u) / u =
    // 1 - u^2/3 + 2u^4/15 - 17u^6/315, 1 / cosh^2 u = 1 - u^2 + 2u^4/3 - 17u^6/45 (u <= 0.002
    // here: the next terms are below 1e-22).
    EXPECT_NEAR(s.x / (0.5 * 9.8 * t * t), 1 - u2 / 6 + u2 * u2 * (2.0 / 45 - u2 * 17.0 / 1260), 2 * eps) << t;
    EXPECT_NEAR(s.v / (9.8 * t), 1 - u2 / 3 + u2 * u2 * (2.0 / 15 - u2 * 17.0 / 315), 2 * eps) << t;
    EXPECT_NEAR(s.a / 9.8, 1 - u2 + u2 * u2 * (2.0 / 3 - u2 * 17.0 / 45), 2 * eps) << t;
  }
  EXPECT_EQ(f.at(0.0).x, 0.0);
  EXPECT_EQ(f.at(0.0).v, 0.0);
  EXPECT_EQ(f.at(-1.0).v, 0.0);  // held before release
  // No drag: exact free fall.
  const falling_drag vacuum = falling_drag::from_mass_and_drag(9.8, 1.0, 0.0);
  EXPECT_TRUE(std::isinf(vacuum.terminal_speed));
  EXPECT_EQ(vacuum.at(3.0).x, 0.5 * 9.8 * 9.0);
  EXPECT_EQ(vacuum.at(3.0).v, 9.8 * 3.0);
  EXPECT_EQ(vacuum.at(3.0).a, 9.8);
}

TEST(falling_drag, large_t_reaches_terminal_speed_without_overflow) {
  const auto f = falling_drag::from_mass_and_drag(9.8, 80.0, 0.25);  // skydiver: v_t = 56 m/s
  EXPECT_NEAR(f.terminal_speed, 56.0, 1e-13);
  // At 60 s (u = 10.5) still 2 e^{-2u} = 1.5e-9 short of v_t; from u ~ 19, v = v_t exactly.
  EXPECT_NEAR(f.at(60.0).v, 56.0 * (1 - 2 * std::exp(-2 * 9.8 * 60.0 / 56.0)), 4 * eps * 56.0);
  for (double t : {200.0, 1e3, 1e6, 1e300}) {
    const auto s = f.at(t);
    ASSERT_TRUE(std::isfinite(s.x) && std::isfinite(s.v) && std::isfinite(s.a)) << t;
    EXPECT_EQ(s.v, 56.0) << t;
    // x -> v_t t - (v_t^2 / g) ln 2 (+ exponentially small).
    const double asym = 56.0 * t - 56.0 * 56.0 / 9.8 * std::numbers::ln2;
    EXPECT_NEAR(s.x, asym, 4 * eps * asym) << t;
    EXPECT_GE(s.a, 0.0);
    EXPECT_LT(s.a, 1e-8);
  }
  EXPECT_NEAR(f.at(10.0).v, 56.0 * std::tanh(9.8 * 10.0 / 56.0), 2 * eps * 56.0);
}

// log_cosh against long double ln(cosh u), and the branches of `at` continuous at their seams.
TEST(falling_drag, log_cosh_accurate_and_branches_continuous) {
  for (double u : {1e-200, 1e-9, 1e-4, 0.3, 1.0, 5.0, 19.999, 20.0, 20.001, 100.0, 1000.0, 11000.0}) {
    // Long double reference; below 1 as log1p(sinh^2) / 2, as cosh(u) - 1 would be lost to
    // long double's own rounding there.
    const ld su = std::sinh(ld(u));
    const ld ref = u < 1.0 ? std::log1p(su * su) / 2 : std::log(std::cosh(ld(u)));
    EXPECT_NEAR(log_cosh(u), double(ref), 3 * eps * double(ref)) << u;
    EXPECT_EQ(log_cosh(-u), log_cosh(u));
  }
  const falling_drag f{9.8, 50.0};
  for (double u_seam : {1e-4, 20.0}) {
    const double t = u_seam * 50.0 / 9.8;
    const auto lo = f.at(std::nextafter(t, 0.0)), hi = f.at(std::nextafter(t, 1e9));
    EXPECT_NEAR(lo.x, hi.x, 8 * eps * hi.x) << u_seam;
    EXPECT_NEAR(lo.v, hi.v, 8 * eps * hi.v) << u_seam;
  }
}

// The closed form satisfies m v' = m g - c v^2, x' = v: by central differences, and against
// RK4 on the ODE itself (h = 1 ms, 30 s: through the transient to terminal speed).
TEST(falling_drag, satisfies_the_ode) {
  const falling_drag f{9.8, 30.0};
  for (double t : {0.01, 0.5, 2.0, 5.0, 12.0}) {
    const double h = 1e-4;
    const auto s = f.at(t), p = f.at(t + h), m = f.at(t - h);
    EXPECT_NEAR((p.x - m.x) / (2 * h), s.v, 1e-8 * 30.0) << t;
    EXPECT_NEAR((p.v - m.v) / (2 * h), s.a, 1e-8 * 9.8) << t;
    EXPECT_NEAR(s.a, acceleration_at_speed(f, s.v), 1e-14 * 9.8) << t;
  }
  const auto rhs = [&](double, const std::array<double, 2>& y) {
    return std::array<double, 2>{y[1], acceleration_at_speed(f, y[1])};
  };
  std::array<double, 2> y{0.0, 0.0};
  const double h = 1e-3;
  for (int i = 1; i <= 30000; ++i) {
    y = rk4_step(rhs, (i - 1) * h, y, h);
    if (i % 1000 == 0) {
      const auto s = f.at(i * h);
      ASSERT_NEAR(y[0], s.x, 1e-11 * s.x) << i * h;
      ASSERT_NEAR(y[1], s.v, 1e-11 * s.v) << i * h;
    }
  }
}

// ---------------------------------------------------------------------------------------
// Block on an incline with friction

double deg(double d) { return d * pi / 180.0; }

// The lecture's friction, kinetic example: sliding down 30 degrees with mu_k = 0.5,
// a = g sin 30 - mu_k g cos 30 = 4.9 (1 - sqrt(3) / 2) = 0.65647552... ~ 0.656 m/s^2.
TEST(sliding_block, lecture_kinetic_example) {
  sliding_block b{9.8, deg(30.0), 0.5, 0.5, -1.0};  // already sliding down at 1 m/s
  const double exact = 4.9 * (1.0 - std::sqrt(3.0) / 2.0);
  EXPECT_NEAR(exact, 0.656, 5e-4);  // the lecture's three digits
  EXPECT_NEAR(b.down_acceleration(), exact, 1e-14);
  EXPECT_EQ(b.stop_time(), std::numeric_limits<double>::infinity());
  for (double t : {0.5, 3.0, 100.0}) {
    const auto s = b.at(t);
    EXPECT_NEAR(s.a, -exact, 1e-14);
    EXPECT_NEAR(s.v, -1.0 - exact * t, 1e-13 * (1 + t));
    EXPECT_NEAR(s.s, -t - 0.5 * exact * t * t, 1e-13 * (1 + t * t));
  }
}

// The lecture's friction, static example: tilting a plane with mu_s = 0.5, the block
// at rest starts to slide at theta = atan(0.5) = 26.565 degrees (the lecture: 26.6).
TEST(sliding_block, lecture_slip_angle) {
  const double slip = std::atan(0.5);
  EXPECT_NEAR(slip * 180.0 / pi, 26.57, 5e-3);
  EXPECT_NEAR(slip * 180.0 / pi, 26.6, 5e-2);
  const sliding_block below{9.8, slip - 1e-9, 0.5, 0.4, 0.0}, above{9.8, slip + 1e-9, 0.5, 0.4, 0.0};
  EXPECT_TRUE(below.stays_at_rest());
  EXPECT_FALSE(above.stays_at_rest());
  EXPECT_EQ(below.at(10.0).s, 0.0);
  EXPECT_EQ(below.at(10.0).v, 0.0);
  // Above: slides down with a = g (sin - mu_k cos) from t = 0.
  const double a = 9.8 * (std::sin(slip + 1e-9) - 0.4 * std::cos(slip + 1e-9));
  EXPECT_NEAR(above.at(2.0).v, -2.0 * a, 1e-14);
  EXPECT_NEAR(above.at(2.0).s, -0.5 * a * 4.0, 1e-14);
  EXPECT_NEAR(above.at(0.0).a, -a, 1e-15);
}

// Pushed up at v0 = 3 m/s on 30 degrees: decelerates at g (sin + mu_k cos), stops at
// t1 = v0 / that, s1 = v0^2 / (2 that), then (tan 30 = 0.577 > mu_s = 0.5) slides back down
// at the lecture's 0.656 m/s^2. Checked piecewise, by work and energy, and at the seam.
TEST(sliding_block, pushed_up_stops_then_slides_back) {
  const sliding_block b{9.8, deg(30.0), 0.5, 0.5, 3.0};
  const double up = 9.8 * (0.5 + 0.5 * std::sqrt(3.0) / 2.0), down = 4.9 * (1.0 - std::sqrt(3.0) / 2.0);
  EXPECT_NEAR(b.up_deceleration(), up, 1e-14);
  EXPECT_FALSE(b.stays_at_rest());
  const double t1 = 3.0 / up, s1 = 9.0 / (2 * up);
  EXPECT_NEAR(b.stop_time(), t1, 1e-15);
  EXPECT_NEAR(b.stop_position(), s1, 1e-15);
  EXPECT_EQ(b.at(0.0).s, 0.0);
  EXPECT_EQ(b.at(0.0).v, 3.0);
  EXPECT_EQ(b.at(b.stop_time()).v, 0.0);
  EXPECT_NEAR(b.at(b.stop_time()).s, s1, 1e-15);
  // Continuous through the stop.
  const double t1d = b.stop_time();
  EXPECT_NEAR(b.at(std::nextafter(t1d, 10.0)).s, s1, 1e-15);
  EXPECT_NEAR(b.at(std::nextafter(t1d, 10.0)).v, 0.0, 1e-15);
  for (double t : {0.1, 0.3, t1 * 0.9}) {
    const auto s = b.at(t);
    EXPECT_NEAR(s.v, 3.0 - up * t, 1e-14);
    EXPECT_NEAR(s.s, 3.0 * t - 0.5 * up * t * t, 1e-14);
    // Work-energy on the way up: (v0^2 - v^2) / 2 = g (sin + mu_k cos) s.
    EXPECT_NEAR(0.5 * (9.0 - s.v * s.v), up * s.s, 1e-13);
  }
  for (double t : {1.0, 2.0, 10.0}) {
    const auto s = b.at(t);
    EXPECT_NEAR(s.a, -down, 1e-14);
    EXPECT_NEAR(s.v, -down * (t - t1), 1e-13);
    EXPECT_NEAR(s.s, s1 - 0.5 * down * (t - t1) * (t - t1), 1e-12);
    // Work-energy on the way down: v^2 / 2 = g (sin - mu_k cos) (s1 - s).
    EXPECT_NEAR(0.5 * s.v * s.v, down * (s1 - s.s), 1e-12);
  }
}

// Static friction holds: after the stop the block stays put forever.
TEST(sliding_block, sticks_when_static_friction_holds) {
  const sliding_block b{9.8, deg(30.0), 0.7, 0.5, 3.0};  // tan 30 = 0.577 <= 0.7
  EXPECT_TRUE(b.stays_at_rest());
  for (double t : {1.0, 1e6}) {
    EXPECT_EQ(b.at(t).s, b.stop_position());
    EXPECT_EQ(b.at(t).v, 0.0);
    EXPECT_EQ(b.at(t).a, 0.0);
  }
  // mu_s < tan theta <= mu_k: static cannot hold, kinetic would stop any motion: rest.
  const sliding_block odd{9.8, deg(30.0), 0.3, 0.7, 3.0};
  EXPECT_TRUE(odd.stays_at_rest());
  EXPECT_EQ(odd.at(100.0).v, 0.0);
  // Thrown down where kinetic friction wins (mu_k = 0.7 > tan 30): decelerates to rest.
  const sliding_block down{9.8, deg(30.0), 0.7, 0.7, -2.0};
  const double dec = 9.8 * (0.7 * std::cos(deg(30.0)) - std::sin(deg(30.0)));
  EXPECT_NEAR(down.stop_time(), 2.0 / dec, 1e-14);
  EXPECT_NEAR(down.at(100.0).s, -2.0 / dec, 1e-14);
  EXPECT_EQ(down.at(100.0).v, 0.0);
  EXPECT_EQ(invalid_reason(sliding_block{}), "");
  EXPECT_NE(invalid_reason(sliding_block{9.8, 2.0, 0.5, 0.5, 1.0}), "");
}

// A time-stepped Coulomb block (semi-implicit Euler, dt = 1e-5, stick when the velocity
// would change sign and static friction holds) follows the piecewise closed form.
TEST(sliding_block, matches_time_stepped_coulomb_model) {
  for (const sliding_block& b :
       {sliding_block{9.8, deg(30.0), 0.5, 0.5, 3.0}, sliding_block{9.8, deg(30.0), 0.7, 0.5, 3.0},
        sliding_block{9.8, deg(20.0), 0.5, 0.3, -1.0}, sliding_block{9.8, deg(40.0), 0.5, 0.4, 0.0}}) {
    const double sn = std::sin(b.theta), cs = std::cos(b.theta), dt = 1e-5;
    double s = 0.0, v = b.v0;
    bool stuck = false;
    for (int i = 1; i <= 300000; ++i) {
      if (!stuck) {
        double a;
        if (v != 0.0) {
          a = -b.g * sn - std::copysign(b.mu_k * b.g * cs, v);
        } else {
          a = sn <= std::max(b.mu_s, b.mu_k) * cs ? 0.0 : -b.g * (sn - b.mu_k * cs);
        }
        const double v_new = v + a * dt;
        if (v != 0.0 && v_new * v < 0.0) {  // friction reversed it: it stopped inside the step
          v = 0.0;
          stuck = sn <= std::max(b.mu_s, b.mu_k) * cs;
        } else {
          v = v_new;
          s += v * dt;
        }
      }
      if (i % 50000 == 0) {
        const auto e = b.at(i * dt);
        EXPECT_NEAR(s, e.s, 2e-4 * (1 + std::abs(e.s))) << "theta " << b.theta << " t " << i * dt;
        EXPECT_NEAR(v, e.v, 2e-4 * (1 + std::abs(e.v))) << "theta " << b.theta << " t " << i * dt;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Friction table

TEST(friction_table, lecture_values_by_name) {
  const auto* ss = find_friction("steel_on_steel");
  ASSERT_NE(ss, nullptr);
  EXPECT_EQ(ss->mu_s_dry, 0.74);
  EXPECT_EQ(ss->mu_k_dry, 0.57);
  EXPECT_EQ(ss->mu_s_lubricated, 0.15);
  EXPECT_EQ(ss->mu_k_lubricated, 0.1);
  const auto* rc = find_friction("rubber_on_concrete");
  ASSERT_NE(rc, nullptr);
  EXPECT_EQ(rc->mu_s_dry, 0.9);
  EXPECT_EQ(rc->mu_k_dry, 0.68);
  const auto* si = find_friction("steel_on_ice");
  ASSERT_NE(si, nullptr);
  EXPECT_EQ(si->mu_s_dry, 0.1);
  EXPECT_EQ(si->mu_k_dry, 0.05);
  const auto* sk = find_friction("ski_on_snow");
  ASSERT_NE(sk, nullptr);
  EXPECT_EQ(sk->mu_s_dry, 0.14);
  EXPECT_EQ(sk->mu_k_dry, 0.05);
  // Empty cells are absent, not 0.
  EXPECT_FALSE(find_friction("brick_on_wood")->mu_k_dry.has_value());
  EXPECT_FALSE(find_friction("cast_iron_on_wood")->mu_s_dry.has_value());
  EXPECT_EQ(find_friction("cast_iron_on_wood")->mu_k_lubricated, 0.075);
  EXPECT_FALSE(find_friction("steel_on_ice")->mu_s_lubricated.has_value());
  EXPECT_EQ(find_friction("wood_on_wood_across_grain")->mu_k_lubricated, 0.072);
  EXPECT_EQ(find_friction("wood_on_wood")->mu_k_dry, 0.30);
  EXPECT_EQ(find_friction("steel_on_steel_"), nullptr);
  EXPECT_EQ(find_friction("steel"), nullptr);
  EXPECT_EQ(find_friction(""), nullptr);
  for (const auto& r : friction_table) EXPECT_EQ(find_friction(friction_name(r)), &r) << friction_name(r);
}

// The header's note on odd entries is complete for the checks a program can make.
TEST(friction_table, odd_entries_are_the_documented_ones) {
  std::vector<std::string> kinetic_above_static, kinetic_equals_static, lubricated_above_dry;
  for (const auto& r : friction_table) {
    const std::string name = friction_name(r);
    for (auto [s, k] : {std::pair{r.mu_s_dry, r.mu_k_dry}, std::pair{r.mu_s_lubricated, r.mu_k_lubricated}}) {
      if (s && k && *k > *s) kinetic_above_static.push_back(name);
      if (s && k && *k == *s) kinetic_equals_static.push_back(name);
    }
    for (auto [dry, lub] : {std::pair{r.mu_s_dry, r.mu_s_lubricated}, std::pair{r.mu_k_dry, r.mu_k_lubricated}})
      if (dry && lub && *lub > *dry) lubricated_above_dry.push_back(name);
    for (auto v : {r.mu_s_dry, r.mu_k_dry, r.mu_s_lubricated, r.mu_k_lubricated})
      if (v) {
        EXPECT_GT(*v, 0.0) << name;
      }
  }
  EXPECT_EQ(kinetic_above_static, std::vector<std::string>{"aluminum_on_aluminum"});
  EXPECT_EQ(kinetic_equals_static, std::vector<std::string>{"steel_on_lead"});
  EXPECT_EQ(lubricated_above_dry, std::vector<std::string>{"ski_on_snow"});
}

// Every cell against the lecture's own table, when the seed is at hand (STEPBENCH_SEED, or
// the shared copy): the numbers as printed, empty cells empty, and each Korean material
// name translated to one English identifier.
TEST(friction_table, matches_the_seed_table) {
  const char* env = std::getenv("STEPBENCH_SEED");
  std::ifstream in(env ? env : "/work/shared/seed/000_710a62d30603e4ec.txt");
  if (!in) GTEST_SKIP() << "seed file not available";
  const std::map<std::string, std::string> english{
      {"알루미늄", "aluminum"},
      {"강철", "steel"},
      {"차 브레이크 패드", "car_brake_pad"},
      {"주철 브레이크 디스크", "cast_iron_brake_disc"},
      {"놋쇠", "brass"},
      {"벽돌", "brick"},
      {"나무", "wood"},
      {"주철", "cast_iron"},
      {"구리", "copper"},
      {"유리", "glass"},
      {"다이아몬드", "diamond"},
      {"금속", "metal"},
      {"니켈", "nickel"},
      {"사람의 관절", "human_joint"},
      {"얼음", "ice"},
      {"가죽", "leather"},
      {"나무(결을 따라)", "wood_along_grain"},
      {"나일론", "nylon"},
      {"나무(결을 가로질러)", "wood_across_grain"},
      {"고무", "rubber"},
      {"아스팔트", "asphalt"},
      {"콘크리트", "concrete"},
      {"은", "silver"},
      {"납", "lead"},
      {"스키", "ski"},
      {"눈", "snow"},
  };
  std::string line;
  while (std::getline(in, line) && line.rfind("알루미늄\t알루미늄\t", 0) != 0) {
  }
  ASSERT_TRUE(in) << "table not found in the seed";
  std::size_t row = 0;
  do {
    std::vector<std::string> cells;
    std::size_t start = 0;
    for (std::size_t tab; (tab = line.find('\t', start)) != std::string::npos; start = tab + 1)
      cells.push_back(line.substr(start, tab - start));
    cells.push_back(line.substr(start));
    if (cells.size() != 6) break;  // the blank line after the table
    ASSERT_LT(row, friction_table.size());
    const auto& r = friction_table[row];
    ASSERT_TRUE(english.count(cells[0]) && english.count(cells[1])) << "row " << row;
    EXPECT_EQ(english.at(cells[0]), r.upper) << "row " << row;
    EXPECT_EQ(english.at(cells[1]), r.lower) << "row " << row;
    const std::array<std::optional<double>, 4> ours{r.mu_s_dry, r.mu_k_dry, r.mu_s_lubricated, r.mu_k_lubricated};
    for (int c = 0; c < 4; ++c) {
      const std::string& cell = cells[2 + c];
      if (cell.empty()) {
        EXPECT_FALSE(ours[c].has_value()) << "row " << row << " column " << c;
      } else {
        ASSERT_TRUE(ours[c].has_value()) << "row " << row << " column " << c;
        EXPECT_EQ(*ours[c], std::strtod(cell.c_str(), nullptr)) << "row " << row << " column " << c;
      }
    }
    ++row;
  } while (std::getline(in, line));
  EXPECT_EQ(row, friction_table.size());
}

// ---------------------------------------------------------------------------------------
// Bouncing ball

// The lecture's response, literally: n = (0, 1), v_n = (v.n) n, v_t = v - v_n,
// v_b = (1 - k_f) v_t - k_r v_n.
std::array<double, 2> respond(std::array<double, 2> v, double k_r, double k_f) {
  const std::array<double, 2> n{0.0, 1.0};
  const double vn = v[0] * n[0] + v[1] * n[1];
  const std::array<double, 2> v_n{vn * n[0], vn * n[1]}, v_t{v[0] - v_n[0], v[1] - v_n[1]};
  return {(1 - k_f) * v_t[0] - k_r * v_n[0], (1 - k_f) * v_t[1] - k_r * v_n[1]};
}

TEST(bouncing_ball, first_contact_and_stable_quadratic) {
  const bouncing_ball b{9.8, 2.0, 1.5, 0.0, 0.8, 0.1};
  EXPECT_NEAR(b.first_contact_time(), std::sqrt(2 * 2.0 / 9.8), 2 * eps);
  EXPECT_NEAR(b.impact_speed(), std::sqrt(2 * 9.8 * 2.0), 4 * eps);
  const auto s0 = b.at(0.0);
  EXPECT_NEAR(s0.z, 2.0, 4 * eps);
  EXPECT_EQ(s0.x, 0.0);
  EXPECT_EQ(s0.vx, 1.5);
  EXPECT_EQ(s0.vz, 0.0);
  EXPECT_EQ(b.at(b.first_contact_time()).z, 0.0);
  // Thrown hard downwards from very low: the textbook (w0 + sqrt(w0^2 + 2 g z0)) / g would
  // cancel completely; the stable form keeps the digits (reference in long double).
  for (auto [z0, w0] : {std::pair{1e-10, -1e5}, std::pair{1e-3, -30.0}, std::pair{5.0, 3.0}, std::pair{0.0, 4.0}}) {
    const ld d = std::sqrt(ld(w0) * w0 + 2 * ld(9.8) * z0);
    const ld ref = w0 > 0 ? (w0 + d) / 9.8L : 2 * ld(z0) / (d - w0);
    EXPECT_NEAR(time_to_ground(z0, w0, 9.8), double(ref), 2 * eps * double(ref)) << z0 << " " << w0;
  }
  EXPECT_EQ(time_to_ground(0.0, -1.0, 9.8), 0.0);
  EXPECT_EQ(invalid_reason(bouncing_ball{}), "");
  EXPECT_NE(invalid_reason(bouncing_ball{9.8, 0.0, 1.0, 0.0, 0.5, 0.0}), "");
  EXPECT_NE(invalid_reason(bouncing_ball{9.8, 1.0, 1.0, 0.0, 1.5, 0.0}), "");
}

// Elastic and frictionless: every bounce back to h, contacts every 2 sqrt(2 h / g).
TEST(bouncing_ball, elastic_bounces_return_to_h_evenly_spaced) {
  const double h = 1.25, g = 9.8, t1 = std::sqrt(2 * h / g);
  const bouncing_ball b{g, h, 0.7, 0.0, 1.0, 0.0};
  EXPECT_TRUE(std::isinf(b.rest_time()));
  const auto contacts = b.contacts_until(200.0);
  ASSERT_EQ(contacts.size(), std::size_t(std::floor((200.0 - t1) / (2 * t1))) + 1);
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto& c = contacts[i];
    EXPECT_NEAR(c.t, t1 + 2 * t1 * double(i), 1e-14 * c.t) << i;
    EXPECT_NEAR(c.x, 0.7 * c.t, 1e-14 * c.x) << i;
    EXPECT_NEAR(c.rebound_height, h, 4 * eps * h) << i;
    const auto apex = b.at(c.t + t1);
    EXPECT_NEAR(apex.z, h, 1e-13) << i;
    EXPECT_NEAR(apex.vz, 0.0, 1e-12) << i;
    EXPECT_EQ(b.contact_index(c.t + t1), c.index);
  }
}

// k_r = 0.5: each rebound reaches a quarter of the previous height; contacts accumulate at
// t_inf = t_1 + 2 v_1 k_r / (g (1 - k_r)) = 3 t_1, after which the ball lies still.
TEST(bouncing_ball, half_restitution_heights_and_accumulation_time) {
  const double h = 2.0, g = 9.8, t1 = std::sqrt(2 * h / g), v1 = std::sqrt(2 * g * h);
  const bouncing_ball b{g, h, 1.0, 0.0, 0.5, 0.2};
  const double t_inf = t1 + 2 * v1 * 0.5 / (g * (1 - 0.5));
  EXPECT_NEAR(t_inf, 3 * t1, 4 * eps * t_inf);
  EXPECT_NEAR(b.rest_time(), t_inf, 4 * eps * t_inf);
  const auto contacts = b.contacts_until(100.0);
  ASSERT_GE(contacts.size(), 20u);
  double previous = h, flight_sum = t1;
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto& c = contacts[i];
    EXPECT_NEAR(c.rebound_height, 0.25 * previous, 8 * eps * previous) << i;
    previous = c.rebound_height;
    EXPECT_LT(c.t, t_inf);
    EXPECT_NEAR(c.t, flight_sum, 4 * eps * t_inf) << i;
    flight_sum += 2 * c.vz_out / g;
    if (i + 1 < contacts.size()) {
      const auto apex = b.at(0.5 * (c.t + contacts[i + 1].t));
      EXPECT_NEAR(apex.z, c.rebound_height, 1e-12 * h) << i;
    }
  }
  // The list stops at the stated threshold: the last rebound below eps * h, the one before not.
  EXPECT_LT(contacts.back().rebound_height, eps * h);
  EXPECT_GE(contacts[contacts.size() - 2].rebound_height, eps * h);
  // Sum of all flights (geometric tail included) is t_inf.
  EXPECT_NEAR(flight_sum + 2 * contacts.back().vz_out / g, t_inf, 8 * eps * t_inf);
  // After t_inf: on the ground, and with k_f > 0 the horizontal motion has died out.
  for (double t : {b.rest_time(), b.rest_time() + 1e-9, 10.0, 1e6}) {
    const auto s = b.at(t);
    EXPECT_EQ(s.z, 0.0);
    EXPECT_EQ(s.vz, 0.0);
    EXPECT_EQ(s.vx, 0.0);
    EXPECT_EQ(s.x, b.rest_position());
  }
  // Just before t_inf it is still (barely) bouncing, and continuous with the rest state.
  const auto late = b.at(std::nextafter(t_inf, 0.0) - 1e-12);
  EXPECT_LT(late.z, 1e-20);
  EXPECT_NEAR(late.x, b.rest_position(), 1e-12);
  // Restitution 0: it stops at the first contact.
  const bouncing_ball dead{g, h, 1.0, 0.0, 0.0, 0.3};
  EXPECT_EQ(dead.rest_time(), dead.first_contact_time());
  EXPECT_EQ(dead.contacts_until(100.0).size(), 1u);
  EXPECT_EQ(dead.at(5.0).z, 0.0);
  EXPECT_EQ(dead.at(5.0).vx, 0.0);
  EXPECT_NEAR(dead.at(5.0).x, t1, 4 * eps);
}

// Energy per unit mass, (vx^2 + vz^2) / 2 + g z: constant in flight; at contact k the
// horizontal part drops by (1 - k_f)^2 and the vertical by k_r^2. With k_f = 1 - k_r the
// total drops by k_r^2 per contact.
TEST(bouncing_ball, energy_bookkeeping_at_contacts) {
  const double g = 9.8, h = 3.0, vx0 = 2.0;
  for (auto [k_r, k_f] : {std::pair{0.8, 0.2}, std::pair{0.6, 0.0}, std::pair{0.9, 0.5}}) {
    const bouncing_ball b{g, h, vx0, 0.0, k_r, k_f};
    const auto contacts = b.contacts_until(1e3);
    const auto energy = [&](const ball_state& s) { return 0.5 * (s.vx * s.vx + s.vz * s.vz) + g * s.z; };
    double horizontal = 0.5 * vx0 * vx0, vertical = g * h;
    EXPECT_NEAR(energy(b.at(0.0)), horizontal + vertical, 1e-14 * (horizontal + vertical));
    for (std::size_t i = 0; i + 1 < contacts.size() && i < 30; ++i) {
      const auto& c = contacts[i];
      EXPECT_NEAR(0.5 * c.vx_out * c.vx_out, (1 - k_f) * (1 - k_f) * 0.5 * c.vx_in * c.vx_in, 1e-15 * horizontal);
      EXPECT_NEAR(0.5 * c.vz_out * c.vz_out, k_r * k_r * 0.5 * c.vz_in * c.vz_in, 1e-14 * vertical);
      horizontal *= (1 - k_f) * (1 - k_f);
      vertical *= k_r * k_r;
      const double t_next = contacts[i + 1].t;
      for (double f : {0.1, 0.5, 0.9}) {
        const auto s = b.at(c.t + f * (t_next - c.t));
        EXPECT_NEAR(energy(s), horizontal + vertical, 1e-12 * (0.5 * vx0 * vx0 + g * h)) << k_r << " " << i << " " << f;
      }
      if (k_f == 1 - k_r) {
        const double before = 0.5 * (c.vx_in * c.vx_in + c.vz_in * c.vz_in);
        const double after = 0.5 * (c.vx_out * c.vx_out + c.vz_out * c.vz_out);
        EXPECT_NEAR(after, k_r * k_r * before, 1e-14 * before);
      }
    }
  }
}

// x after n bounces is vx0 (t_1 + D (q + ... + q^{n-1})), q = (1 - k_f) k_r, D = 2 v_1 / g;
// the geometric sum summed term by term here.
TEST(bouncing_ball, horizontal_position_is_the_geometric_sum) {
  const double g = 9.8, h = 1.0, vx0 = 3.0, k_r = 0.7, k_f = 0.25, q = (1 - k_f) * k_r;
  const bouncing_ball b{g, h, vx0, 0.0, k_r, k_f};
  const double t1 = std::sqrt(2 * h / g), D = 2 * std::sqrt(2 * g * h) / g;
  double sum = 0.0, term = 1.0;
  for (long long n = 1; n <= 60; ++n) {
    EXPECT_NEAR(b.contact_position(n), vx0 * (t1 + D * sum), 1e-14 * vx0 * (t1 + D / (1 - q))) << n;
    term *= q;
    sum += term;
  }
  EXPECT_NEAR(b.rest_position(), vx0 * (t1 + D * q / (1 - q)), 1e-14 * b.rest_position());
  // Without friction x = vx0 t throughout, and after t_inf it keeps sliding at vx0.
  const bouncing_ball slick{g, h, vx0, 0.0, k_r, 0.0};
  for (double t : {0.3, 1.0, 2.0, slick.rest_time(), 50.0}) {
    EXPECT_NEAR(slick.at(t).x, vx0 * t, 1e-14 * vx0 * t) << t;
    EXPECT_EQ(slick.at(t).vx, t < slick.rest_time() ? vx0 : slick.rest_speed());
  }
  EXPECT_EQ(slick.rest_speed(), vx0);
}

// An independent event-driven simulation: fly each parabola exactly, find the landing by the
// stable quadratic from the current state, apply the lecture's response literally. Launched
// upwards (vz0 > 0) so the first flight is a general quadratic.
TEST(bouncing_ball, matches_event_driven_simulation) {
  const double g = 9.81;
  for (auto [k_r, k_f] : {std::pair{0.9, 0.1}, std::pair{0.5, 0.0}, std::pair{1.0, 0.3}, std::pair{0.999, 0.001}}) {
    const bouncing_ball b{g, 0.7, -1.2, 2.5, k_r, k_f};
    double t = 0.0, x = 0.0, z = 0.7;
    std::array<double, 2> v{-1.2, 2.5};
    for (long long k = 1; k <= 200; ++k) {
      const double tau = time_to_ground(z, v[1], g);
      t += tau;
      x += v[0] * tau;
      v[1] -= g * tau;
      z = 0.0;
      const auto c = b.contact(k);
      ASSERT_NEAR(c.t, t, 1e-12 * t) << k_r << " contact " << k;
      ASSERT_NEAR(c.x, x, 1e-12 * (1 + std::abs(x))) << k_r << " contact " << k;
      ASSERT_NEAR(c.vx_in, v[0], 1e-13) << k;
      ASSERT_NEAR(c.vz_in, v[1], 1e-12) << k;
      v = respond(v, k_r, k_f);
      ASSERT_NEAR(c.vx_out, v[0], 1e-13) << k;
      ASSERT_NEAR(c.vz_out, v[1], 1e-12) << k;
      if (c.rebound_height < 1e-10) break;
      // Mid-flight state from the closed form against the simulated parabola.
      const double half = v[1] / g;
      const auto s = b.at(t + half);
      EXPECT_NEAR(s.x, x + v[0] * half, 1e-12 * (1 + std::abs(x)));
      EXPECT_NEAR(s.z, v[1] * half - 0.5 * g * half * half, 1e-12);
      EXPECT_NEAR(s.vz, 0.0, 1e-11);
    }
  }
}

// The closed form is continuous and satisfies x'' = 0, z'' = -g between contacts, and the
// O(1) contact index agrees with the contact times, far into the Zeno cascade.
TEST(bouncing_ball, state_consistent_between_contacts) {
  const bouncing_ball b{9.8, 1.0, 0.5, 0.0, 0.6, 0.1};
  const auto contacts = b.contacts_until(1e9, 0.0);
  ASSERT_GT(contacts.size(), 30u);
  for (std::size_t i = 0; i + 1 < contacts.size(); ++i) {
    const double ta = contacts[i].t, tb = contacts[i + 1].t;
    if (!(tb > ta)) break;
    EXPECT_EQ(b.contact_index(ta), contacts[i].index);
    EXPECT_EQ(b.contact_index(std::nextafter(tb, 0.0)), contacts[i].index);
    EXPECT_EQ(b.at(ta).z, 0.0);
    EXPECT_GE(b.at(0.5 * (ta + tb)).z, 0.0);
    if (i < 12) {
      const double t = ta + 0.37 * (tb - ta), hstep = 1e-3 * (tb - ta);
      const auto s = b.at(t), p = b.at(t + hstep), m = b.at(t - hstep);
      EXPECT_NEAR((p.z - m.z) / (2 * hstep), s.vz, 1e-6 * b.impact_speed());
      EXPECT_NEAR((p.x - m.x) / (2 * hstep), s.vx, 1e-9);
      EXPECT_NEAR((p.vz - m.vz) / (2 * hstep), -9.8, 1e-6 * 9.8);
      // Continuity of x and the contact's velocities.
      EXPECT_NEAR(b.at(std::nextafter(ta, 0.0)).x, b.at(ta).x, 1e-14);
      EXPECT_NEAR(b.at(ta).vz, contacts[i].vz_out, 1e-14);
      EXPECT_NEAR(b.at(std::nextafter(ta, 0.0)).vz, contacts[i].vz_in, 1e-12);
    }
  }
}

// The contact index brackets t exactly, also within a few ulps of t_inf and for k_r -> 1,
// where the guess from the logarithm is hundreds of bounces off.
TEST(bouncing_ball, contact_index_brackets_t_up_to_the_accumulation_time) {
  for (double k_r : {0.1, 0.5, 0.9, 0.999, 1 - 1e-9}) {
    const bouncing_ball b{9.8, 1.0, 0.5, 0.0, k_r, 0.05};
    const double t1 = b.first_contact_time(), t_inf = b.rest_time();
    std::vector<double> times;
    for (int j = 0; j <= 60; ++j) times.push_back(t_inf - std::ldexp(t_inf - t1, -j));
    double t = t_inf;
    for (int j = 0; j < 8; ++j) times.push_back(t = std::nextafter(t, 0.0));
    for (double tt : times) {
      if (!(tt >= t1 && tt < t_inf)) continue;
      const long long k = b.contact_index(tt);
      ASSERT_LE(b.contact_time(k), tt) << k_r << " " << tt;
      ASSERT_GT(b.contact_time(k + 1), tt) << k_r << " " << tt;
      const auto s = b.at(tt);
      ASSERT_GE(s.z, 0.0);
      ASSERT_TRUE(std::isfinite(s.x) && std::isfinite(s.vx) && std::isfinite(s.vz));
    }
  }
}

}  // namespace

}  // namespace stepbench::exact

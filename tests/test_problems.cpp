// The lecture's worked examples and the closed forms of the problems.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>

#include "core/drive.hpp"
#include "integrators/all.hpp"
#include "problems/bouncing_ball.hpp"
#include "problems/constant_acceleration.hpp"
#include "problems/damped_spring.hpp"
#include "problems/pendulum.hpp"
#include "problems/projectile.hpp"
#include "problems/sliding_block.hpp"
#include "problems/spring_chain.hpp"

using namespace stepbench;

namespace {

// The lecture's projectile formulas, launch and landing at the same height.
double apex_time(const projectile& p) { return p.launch_velocity().z() / p.gravity; }
double apex_height(const projectile& p) {
  const double vz = p.launch_velocity().z();
  return vz * vz / (2.0 * p.gravity);
}
double range(const projectile& p) { return p.speed * p.speed * std::sin(2.0 * p.angle_rad()) / p.gravity; }

// Launch angle (radians) that reaches apex height h above the launch point at speed s:
// a = asin( sqrt(2 g h) / s ). Returns NaN when h is out of reach.
double launch_angle_for_height(double h, double s, double g) { return std::asin(std::sqrt(2.0 * g * h) / s); }

// The two launch angles (radians) that land at range r: a = asin(r g / s^2) / 2 and
// pi/2 - a. NaN when r is beyond the maximum range s^2 / g.
std::array<double, 2> launch_angles_for_range(double r, double s, double g) {
  const double low = 0.5 * std::asin(r * g / (s * s));
  return {low, std::numbers::pi / 2.0 - low};
}

// Friction on an incline (the lecture's forces): its two worked examples are closed-form.
namespace incline {

// Normal force on an incline of angle theta: |F_n| = m g cos(theta).
double normal_force(double mass, double g, double theta) { return mass * g * std::cos(theta); }

// Acceleration down the slope of a sliding block with kinetic friction mu_k:
// a = g sin(theta) - mu_k g cos(theta). Negative means kinetic friction would stop it.
double sliding_acceleration(double g, double theta, double mu_k) {
  return g * std::sin(theta) - mu_k * g * std::cos(theta);
}

// Tilt at which a block at rest starts to slide: m g sin(theta) = mu_s m g cos(theta),
// so theta = atan(mu_s).
double sliding_angle(double mu_s) { return std::atan(mu_s); }

}  // namespace incline

template <class I, class P>
phase<typename P::vec> final_state(const P& p, double dt, double horizon) {
  return drive(p, I{}, dt, horizon, std::span<const record_point>{}).final_state;
}

// Checks x'' = F(t, x, x') / m for a closed form by central differences at t.
template <class P>
void expect_satisfies_ode(const P& p, double t, double tol) {
  const double h = 1e-5;  // truncation h^2 x''' / 6 stays below 1e-7 for the stiffest case here
  const auto s = p.exact(t);
  const auto xp = p.exact(t + h).x, xm = p.exact(t - h).x;
  const auto vp = p.exact(t + h).v, vm = p.exact(t - h).v;
  typename P::vec f = s.x;
  p.force(t, s.x, s.v, f);
  for (int i = 0; i < p.dim(); ++i) {
    EXPECT_NEAR((xp[i] - xm[i]) / (2 * h), s.v[i], tol) << P::name << " x' at t=" << t;
    EXPECT_NEAR((vp[i] - vm[i]) / (2 * h), f[i] / p.mass(), tol) << P::name << " v' at t=" << t;
  }
}

}  // namespace

// The lecture's explicit Euler worked example (integration): 10 N on 1 kg from rest,
// 10 s, dt = 1 s. Exact 500 m; explicit Euler 450 m (the lecture's 470 m is wrong);
// semi-implicit Euler 550 m.
TEST(lecture, euler_example_distances) {
  const constant_acceleration p;
  EXPECT_DOUBLE_EQ(p.exact(10.0).x[0], 500.0);
  EXPECT_DOUBLE_EQ((final_state<euler>(p, 1.0, 10.0).x[0]), 450.0);
  EXPECT_DOUBLE_EQ((final_state<semi_implicit_euler>(p, 1.0, 10.0).x[0]), 550.0);
  EXPECT_DOUBLE_EQ((final_state<momentum>(p, 1.0, 10.0).x[0]), 550.0);
  // Second order and up are exact for constant acceleration.
  EXPECT_DOUBLE_EQ((final_state<midpoint>(p, 1.0, 10.0).x[0]), 500.0);
  EXPECT_DOUBLE_EQ((final_state<rk4>(p, 1.0, 10.0).x[0]), 500.0);
  EXPECT_DOUBLE_EQ((final_state<velocity_verlet>(p, 1.0, 10.0).x[0]), 500.0);
}

// The lecture's loop runs `while (t <= 10)`: eleven explicit Euler steps, 550 m; not
// 470 m either way.
TEST(lecture, euler_example_eleven_steps) {
  const constant_acceleration p;
  EXPECT_DOUBLE_EQ((final_state<euler>(p, 1.0, 11.0).x[0]), 550.0);
}

// The lecture's projectile motion: 50 m/s at 70 degrees, g = 9.8. Range s^2 sin(2a) / g,
// apex
// vz^2 / (2 g), flight time 2 vz / g (values computed independently in double
// precision from those formulas).
TEST(lecture, projectile_range_apex_flight_time) {
  const projectile p;
  EXPECT_NEAR(range(p), 163.97643104248456, 1e-10);
  EXPECT_NEAR(apex_height(p), 112.63038540299603, 1e-10);
  EXPECT_NEAR(p.flight_time(), 9.588700212101104, 1e-12);
  EXPECT_DOUBLE_EQ(p.horizon(), p.flight_time());
  // The closed form lands at the range, at launch height, and peaks at the apex.
  EXPECT_NEAR(p.exact(p.flight_time()).x.x(), range(p), 1e-10);
  EXPECT_NEAR(p.exact(p.flight_time()).x.z(), 0.0, 1e-10);
  EXPECT_NEAR(p.exact(apex_time(p)).x.z(), apex_height(p), 1e-10);
  EXPECT_NEAR(p.exact(apex_time(p)).v.z(), 0.0, 1e-12);
  // RK4 is exact on uniform gravity: it lands on the range with only 10 steps.
  const auto s = final_state<rk4>(p, p.horizon() / 10, p.horizon());
  EXPECT_NEAR(s.x.x(), range(p), 1e-10);
  EXPECT_NEAR(s.x.z(), 0.0, 1e-10);
  // The inverse formulas recover the launch angle.
  EXPECT_NEAR(launch_angle_for_height(apex_height(p), p.speed, p.gravity), p.angle_rad(), 1e-12);
  const auto angles = launch_angles_for_range(range(p), p.speed, p.gravity);
  EXPECT_NEAR(angles[1], p.angle_rad(), 1e-12);
  EXPECT_NEAR(angles[0], std::numbers::pi / 2 - p.angle_rad(), 1e-12);
}

// The lecture's friction (forces): block on a 30 degree incline, mu_k = 0.5:
// a = g sin - mu_k g cos,
// about 0.656 m/s^2; static mu_s = 0.5 slides from atan(0.5), about 26.57 degrees.
TEST(lecture, incline_acceleration_and_sliding_angle) {
  const double theta = 30.0 * std::numbers::pi / 180.0;
  EXPECT_NEAR(incline::sliding_acceleration(9.8, theta, 0.5), 0.6564755214562499, 1e-12);
  EXPECT_NEAR(incline::sliding_angle(0.5) * 180.0 / std::numbers::pi, 26.56505117707799, 1e-10);
  EXPECT_NEAR(incline::normal_force(10.0, 9.8, theta), 98.0 * std::sqrt(3.0) / 2.0, 1e-12);
}

TEST(damped_spring, closed_form_all_regimes) {
  for (double k_d : {0.0, 1.0, 2.0 * std::sqrt(10.0), 2.0 * std::sqrt(10.0) * (1 + 1e-9), 15.0}) {
    damped_spring p;
    p.k_d = k_d;
    p.v0 = -0.7;
    const auto s0 = p.exact(0.0);
    EXPECT_NEAR(s0.x[0], p.x0, 1e-15) << "k_d " << k_d;
    EXPECT_NEAR(s0.v[0], p.v0, 1e-14) << "k_d " << k_d;
    for (double t : {0.3, 1.7, 4.0, 9.5}) expect_satisfies_ode(p, t, 1e-6);
  }
}

// Near-critical damping must not lose accuracy: the closed form is continuous in k_d.
TEST(damped_spring, closed_form_continuous_through_critical) {
  damped_spring crit, under, over;
  crit.k_d = 2.0 * std::sqrt(10.0);
  under.k_d = crit.k_d * (1 - 1e-10);
  over.k_d = crit.k_d * (1 + 1e-10);
  for (double t : {0.5, 2.0, 8.0}) {
    EXPECT_NEAR(under.exact(t).x[0], crit.exact(t).x[0], 1e-8);
    EXPECT_NEAR(over.exact(t).x[0], crit.exact(t).x[0], 1e-8);
  }
  damped_spring very_over;  // large gamma t must not overflow cosh or underflow to NaN
  very_over.k_d = 2000.0;
  EXPECT_TRUE(std::isfinite(very_over.exact(1000.0).x[0]));
}

// Heavy damping (gamma = 5e4 >> w0 = 3.16) at small and large t: x and v against the
// two-exponential form c1 e^{r1 t} + c2 e^{r2 t} evaluated in long double. The velocity is
// a small difference of terms of size gamma in the textbook form; it must keep its digits.
TEST(damped_spring, closed_form_keeps_digits_under_heavy_damping) {
  damped_spring p;
  p.k_d = 1e5;
  p.v0 = -0.7;
  using ld = long double;
  const ld g = 5e4L, w2 = 10.0L, s = std::sqrt(g * g - w2), r1 = -g + s, r2 = -g - s;
  const ld c1 = (ld(p.v0) - r2 * p.x0) / (2 * s), c2 = (r1 * p.x0 - ld(p.v0)) / (2 * s);
  for (double t : {1e-7, 1e-5, 1e-3, 0.3, 5.0}) {
    const ld x = c1 * std::exp(r1 * t) + c2 * std::exp(r2 * t);
    const ld v = r1 * c1 * std::exp(r1 * t) + r2 * c2 * std::exp(r2 * t);
    const auto e = p.exact(t);
    EXPECT_NEAR(e.x[0], static_cast<double>(x), 1e-13 * std::abs(static_cast<double>(x))) << "t " << t;
    EXPECT_NEAR(e.v[0], static_cast<double>(v), 1e-11 * std::abs(static_cast<double>(v))) << "t " << t;
  }
}

// K(k) for k = sin 60 deg, i.e. m = k^2 = 3/4: 2.156515647499643 (Abramowitz & Stegun
// table 17.1; scipy.special.ellipk(0.75) gives the same to 16 digits).
TEST(pendulum, exact_period_from_elliptic_integral) {
  const pendulum p;  // 120 degrees
  EXPECT_NEAR(p.quarter_period_k(), 2.156515647499643, 1e-14);
  EXPECT_NEAR(p.period(), 4.0 * 2.156515647499643 / std::sqrt(9.8), 1e-13);
  // The large swing is 37 % slower than the small-angle period 2 pi sqrt(L/g).
  EXPECT_NEAR(p.period() / (2 * std::numbers::pi / std::sqrt(9.8)), 1.3728, 1e-4);
  // After one exact period the closed form is back at rest at theta0.
  EXPECT_NEAR(p.exact(p.period()).x[0], p.theta0(), 1e-12);
  EXPECT_NEAR(p.exact(p.period()).v[0], 0.0, 1e-12);
  // At a quarter period it passes the bottom at the speed energy conservation gives.
  EXPECT_NEAR(p.exact(p.period() / 4).x[0], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(p.exact(p.period() / 4).v[0]), std::sqrt(2 * 9.8 * (1 - std::cos(p.theta0()))), 1e-12);
}

// Near the top, K grows like ln(4 / k') and k = sin(theta0/2) -> 1 loses the digits that
// matter; the AGM on k' = cos(theta0/2) keeps them. Values from mpmath.ellipk at 40 digits
// for the binary doubles 179.0 and 179.9999 (not the decimal 179.9999, which differs by
// 1e-10 relative in k' this close to the top), g = 9.8.
TEST(pendulum, period_near_the_top) {
  pendulum p;
  p.theta0_deg = 179.0;
  EXPECT_NEAR(p.quarter_period_k(), 6.127778824526720, 1e-13);
  p.theta0_deg = 179.9999;
  EXPECT_NEAR(p.quarter_period_k(), 15.33800887866649, 1e-12);
  EXPECT_NEAR(p.period(), 19.59818885268205, 1e-12);
}

TEST(pendulum, closed_form_satisfies_ode_and_conserves_energy) {
  const pendulum p;
  const auto s0 = p.initial();
  for (double t : {0.1, 0.9, 2.2, 4.4}) {
    expect_satisfies_ode(p, t, 1e-6);
    const auto s = p.exact(t);
    EXPECT_NEAR(p.energy(s.x, s.v), p.energy(s0.x, s0.v), 1e-12);
  }
}

TEST(problems, validate_rejects_bad_parameters) {
  pendulum p;
  p.theta0_deg = 180.0;
  EXPECT_EQ(validate(p), "theta0_deg must be in (0, 180)");
  damped_spring d;
  d.mass_kg = 0.0;
  EXPECT_EQ(validate(d), "mass_kg must be a positive finite number");
  d = {};
  d.k_d = -1.0;
  EXPECT_EQ(validate(d), "k_d must be finite and >= 0");
  projectile pr;
  pr.speed = std::nan("");
  EXPECT_EQ(validate(pr), "speed must be a positive finite number");
  spring_chain c;
  c.masses = 2.5;
  EXPECT_EQ(validate(c), "masses must be a whole number from 2 to 1048576");
  bouncing_ball b;
  b.locate = 2;
  EXPECT_EQ(validate(b), "locate must be 0 (end_of_step) or 1 (locate)");
  EXPECT_EQ(validate(constant_acceleration{}), "");
}

// Each parameter is declared once; what --set, `list` and the study file see derives
// from it: the declaration's default, its constraint, and its names.
TEST(problems, parameters_are_declared_once) {
  pendulum p;
  p.theta0_deg = 150.0;
  const auto params = declared_params(p);
  ASSERT_EQ(params.size(), 5u);
  EXPECT_EQ(params[3].name, "theta0_deg");
  EXPECT_EQ(params[3].unit, "deg");
  EXPECT_EQ(params[3].value, 150.0);
  EXPECT_EQ(params[3].default_value, 120.0);
  EXPECT_EQ(params[3].kind(), "real");
  EXPECT_FALSE(params[3].allowed.admits(0.0));
  EXPECT_TRUE(params[3].allowed.admits(179.9));
  EXPECT_FALSE(params[3].allowed.admits(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(params[3].parse("90", "pendulum.theta0_deg"), 90.0);
  EXPECT_THROW(params[3].parse("90x", "pendulum.theta0_deg"), std::invalid_argument);

  const auto chain = declared_params(spring_chain{});
  EXPECT_EQ(chain[0].kind(), "whole");
  const auto block = declared_params(sliding_block{});
  const auto& material = block[4];
  EXPECT_EQ(material.name, "material");
  EXPECT_EQ(material.kind(), "named");
  EXPECT_EQ(material.parse("steel_on_steel", "sliding_block.material"), friction_row("steel_on_steel"));
  EXPECT_EQ(material.value_name(), "none");
  try {
    material.parse("unobtainium", "sliding_block.material");
    ADD_FAILURE() << "unobtainium was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("steel_on_steel"), std::string::npos) << e.what();
  }
}

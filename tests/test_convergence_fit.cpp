// The order fit on synthetic ladders with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "core/convergence_fit.hpp"

using namespace stepbench;

namespace {

fit_input ladder(int levels, auto error_of_dt) {
  fit_input in;
  for (int k = 0; k < levels; ++k) {
    const double dt = 0.5 / std::ldexp(1.0, k);
    in.dt.push_back(dt);
    in.error.push_back(error_of_dt(dt));
    in.steps.push_back(20L << k);
    in.incomplete.push_back(false);
  }
  return in;
}

}  // namespace

TEST(fit, recovers_a_pure_power_law) {
  const auto r = fit_order(ladder(8, [](double dt) { return 3e-3 * std::pow(dt, 2); }));
  ASSERT_EQ(r.state, fit_result::status::fitted);
  EXPECT_NEAR(r.order, 2.0, 1e-12);
  EXPECT_NEAR(r.intercept, std::log10(3e-3), 1e-10);
  EXPECT_EQ(r.levels.size(), 8u);
}

// Pre-asymptotic levels (error saturating at the motion's size) and a round-off floor
// at the fine end are left out; the levels used are the clean power-law ones.
TEST(fit, skips_preasymptotic_and_roundoff_levels) {
  auto in = ladder(12, [](double dt) { return 5e-2 * std::pow(dt, 4) + 1e-15; });
  in.error[0] = 0.5;  // saturated: above 10 % of the unit scale
  const auto r = fit_order(in);
  ASSERT_EQ(r.state, fit_result::status::fitted);
  EXPECT_NEAR(r.order, 4.0, 0.02);
  EXPECT_EQ(r.levels.front(), 1);
  EXPECT_LT(r.levels.back(), 11);  // the finest levels sit at the 1e-15 floor
}

TEST(fit, diverged_levels_are_excluded) {
  auto in = ladder(8, [](double dt) { return 1e-2 * dt; });
  in.incomplete[0] = in.incomplete[1] = true;
  in.error[0] = in.error[1] = NAN;
  const auto r = fit_order(in);
  ASSERT_EQ(r.state, fit_result::status::fitted);
  EXPECT_NEAR(r.order, 1.0, 1e-12);
  EXPECT_EQ(r.levels.front(), 2);
}

TEST(fit, roundoff_everywhere_is_exact) {
  const auto r = fit_order(ladder(8, [](double) { return 1e-16; }));
  EXPECT_EQ(r.state, fit_result::status::exact);
  EXPECT_TRUE(std::isnan(r.order));
  EXPECT_TRUE(r.levels.empty());
}

// A change of slope (order 1 at large dt turning into order 2) is not averaged: the
// fit keeps the fine end, where the asymptotic behaviour is.
TEST(fit, keeps_the_fine_end_of_a_slope_change) {
  const auto r = fit_order(ladder(10, [](double dt) { return dt < 0.03 ? 1e-2 * dt * dt : 3e-4 * dt / 0.03; }));
  ASSERT_EQ(r.state, fit_result::status::fitted);
  EXPECT_NEAR(r.order, 2.0, 1e-9);
}

TEST(fit, too_few_levels_is_insufficient) {
  const auto r = fit_order(ladder(2, [](double dt) { return dt; }));
  EXPECT_EQ(r.state, fit_result::status::insufficient);
  EXPECT_FALSE(r.note.empty());
}

// On a ladder of a billion steps the round-off bound 8 eps n scale is ~2e-6, above a
// first-order method's truncation error there; halving errors are convergence, not
// exactness.
TEST(fit, converging_errors_under_a_large_bound_are_not_exact) {
  fit_input in;
  for (int k = 0; k < 3; ++k) {
    in.dt.push_back(1e-9 / std::ldexp(1.0, k));
    in.error.push_back(9e-7 / std::ldexp(1.0, k));
    in.steps.push_back(1000000000L << k);
    in.incomplete.push_back(false);
  }
  ASSERT_LT(in.error[0], roundoff_bound(in.steps[0], 1.0));
  const auto r = fit_order(in);
  EXPECT_NE(r.state, fit_result::status::exact);
  EXPECT_NEAR(r.order, 1.0, 1e-9);
}

// The finest usable pair is the first touch of round-off (its slope is off by 0.5): the
// window that starts there has only two levels, so the fit moves one level coarser and
// still finds the clean order-4 range.
TEST(fit, an_odd_finest_pair_does_not_hide_the_asymptotic_range) {
  auto in = ladder(8, [](double dt) { return 1e-1 * std::pow(dt, 4); });
  in.error[7] = in.error[6] / std::pow(2.0, 3.5);  // slope 3.5 at the fine end
  const auto r = fit_order(in);
  ASSERT_EQ(r.state, fit_result::status::fitted) << r.note;
  EXPECT_NEAR(r.order, 4.0, 1e-9);
  EXPECT_EQ(r.levels.back(), 6);
}

// Round-off that grows faster than the random walk reaches the levels before the rise.
// xpbd on n_pendulum (full study at 3a53ac5, levels 0..17 of the 60 Hz ladder): the
// error halves to level 12 (slope 1.00), then 1.11 and 1.14, then rises. The levels
// just before the rise are not the asymptotic range: the fit ends two levels earlier.
TEST(fit, the_levels_before_a_roundoff_rise_are_left_out) {
  fit_input in;
  const double err[] = {0.15734340568538097,   0.08041570863886992,    0.04108572409422652,    0.021013792699352038,
                        0.010661544044029973,  0.005374756912146361,   0.00269909421386244,    0.001352569813874764,
                        0.0006770523687635662, 0.00033871951700500675, 0.00016940905407504718, 8.472105676144979e-05,
                        4.23913064080766e-05,  2.1231364918808608e-05, 9.844375604998209e-06,  4.47234441003712e-06,
                        5.553703818823655e-06, 2.3130483813448354e-05};
  for (int k = 0; k < 18; ++k) {
    in.dt.push_back(1.0 / (60.0 * std::ldexp(1.0, k)));
    in.error.push_back(err[k]);
    in.steps.push_back(32L << k);
    in.incomplete.push_back(false);
  }
  in.scale = 1.2;
  const auto r = fit_order(in);
  ASSERT_EQ(r.state, fit_result::status::fitted) << r.note;
  EXPECT_NEAR(r.order, 1.0, 0.02);
  EXPECT_LE(r.levels.back(), 13);
  EXPECT_GE(r.levels.size(), 10u);
  // Without the rise (the ladder ends at level 15) the finest window is taken as before.
  for (auto* v : {&in.dt, &in.error}) v->resize(16);
  in.steps.resize(16), in.incomplete.resize(16);
  EXPECT_EQ(fit_order(in).levels.back(), 15);
}

// The convergence sweep end to end: observed orders, exactness, and the references
// against the closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "core/sweep.hpp"

using namespace stepbench;

namespace {

const study& default_study() {
  static const study s = run_sweep(sweep_options{});
  return s;
}

const problem_study& find(const study& s, std::string_view name) {
  for (const auto& p : s.problems)
    if (p.problem->name() == name) return p;
  throw std::runtime_error("problem not in study");
}

}  // namespace

// The bar: observed order within 0.15 of expected on damped_spring and pendulum
// for every integrator, from a fit over at least three levels.
TEST(sweep, observed_orders_match_expected) {
  for (const char* name : {"damped_spring", "pendulum"}) {
    const auto& ps = find(default_study(), name);
    ASSERT_EQ(ps.integrators.size(), 6u);
    for (const auto& is : ps.integrators) {
      ASSERT_EQ(is.fit.state, fit_result::status::fitted) << name << "/" << is.info.name << ": " << is.fit.note;
      EXPECT_NEAR(is.fit.order, is.info.order, 0.15) << name << "/" << is.info.name;
      EXPECT_GE(is.fit.levels.size(), 3u) << name << "/" << is.info.name;
    }
  }
}

TEST(sweep, ladder_has_at_least_eight_halving_levels) {
  const auto& ps = find(default_study(), "pendulum");
  const auto& rows = ps.integrators.front().rows;
  ASSERT_GE(rows.size(), 8u);
  for (size_t k = 1; k < rows.size(); ++k) {
    EXPECT_DOUBLE_EQ(rows[k - 1].dt, 2.0 * rows[k].dt);
    EXPECT_EQ(rows[k].steps, 2 * rows[k - 1].steps);
  }
}

// Methods of order >= 2 integrate a constant force exactly (the solution is quadratic
// in t); the fit must say "exact", not fit a slope to round-off. First-order methods
// are not exact and fit order 1.
TEST(sweep, exact_methods_on_constant_acceleration) {
  for (const char* name : {"constant_acceleration", "projectile"}) {
    const auto& ps = find(default_study(), name);
    for (const auto& is : ps.integrators) {
      if (is.info.order >= 2) {
        EXPECT_EQ(is.fit.state, fit_result::status::exact) << name << "/" << is.info.name;
        EXPECT_TRUE(std::isnan(is.fit.order));
      } else {
        ASSERT_EQ(is.fit.state, fit_result::status::fitted) << name << "/" << is.info.name;
        EXPECT_NEAR(is.fit.order, 1.0, 0.05) << name << "/" << is.info.name;
      }
    }
  }
}

// Both references (GSL rk8pd, CVODE BDF and Adams) agree with the closed forms to 1e-9
// relative to the motion's amplitude, at every sample time.
TEST(sweep, references_agree_with_closed_forms) {
  for (const char* name : {"damped_spring", "pendulum"}) {
    const auto& ps = find(default_study(), name);
    EXPECT_EQ(ps.truth.source, "closed_form");
    ASSERT_EQ(ps.truth.references.size(), 3u);
    for (const auto& r : ps.truth.references) {
      EXPECT_EQ(r.compared_with, "closed_form");
      EXPECT_LT(r.vs.pos_rel, 1e-9) << name << "/" << r.solution.source;
      EXPECT_LT(r.vs.vel_rel, 1e-9) << name << "/" << r.solution.source;
      EXPECT_GT(r.solution.stats.steps, 0);
    }
  }
}

// Without the closed form, the truth is the best-agreeing reference, and the errors
// measured against it match those measured against the closed form.
TEST(sweep, references_stand_in_for_a_missing_closed_form) {
  auto p = make_problem("pendulum");
  const double T = p->horizon();
  std::vector<double> times;
  for (int j = 1; j <= 32; ++j) times.push_back(j == 32 ? T : T * j / 32);
  const auto with = build_truth(*p, times, {});
  const auto without = build_truth(*p, times, {.use_closed_form = false});
  EXPECT_NE(without.source, "closed_form");
  const auto a = compare(with.y, without.y, 1, with.pos_scale, with.vel_scale);
  EXPECT_LT(a.worst(), 1e-9);
  for (const auto& r : without.references) EXPECT_FALSE(r.compared_with.empty());
}

// A reference that disagrees beyond the agreement limit is an error, not a pass: loose
// solver tolerances against a strict limit must throw.
TEST(sweep, disagreeing_reference_is_an_error) {
  auto p = make_problem("pendulum");
  const std::vector<double> times{p->horizon()};
  truth_options opts;
  opts.tol = {.rtol = 1e-4, .atol = 1e-4};
  opts.agreement_limit_factor = 1e-4;  // limit 1e-8 against references good to ~1e-4
  EXPECT_THROW(build_truth(*p, times, opts), std::runtime_error);
}

TEST(sweep, overrides_reach_the_problem) {
  sweep_options opts;
  opts.problems = {"pendulum"};
  opts.integrators = {"rk4"};
  opts.levels = 3;
  opts.overrides["pendulum"]["theta0_deg"] = 10.0;
  const auto s = run_sweep(opts);
  const auto params = s.problems.front().problem->params();
  bool found = false;
  for (const auto& q : params)
    if (q.name == "theta0_deg") {
      found = true;
      EXPECT_DOUBLE_EQ(q.value, 10.0);
    }
  EXPECT_TRUE(found);
}

TEST(sweep, invalid_options_are_rejected) {
  sweep_options opts;
  opts.problems = {"no_such_problem"};
  EXPECT_THROW(validate(opts), std::invalid_argument);
  opts = {};
  opts.integrators = {"rk5"};
  EXPECT_THROW(validate(opts), std::invalid_argument);
  opts = {};
  opts.overrides["pendulum"]["length_m"] = -1.0;
  EXPECT_THROW(validate(opts), std::invalid_argument);
}

// Explicit Euler on m x'' + c x' + k x = 0 multiplies each mode by 1 + h lambda, lambda =
// -gamma +- i w_d, so it is stable iff h < 2 gamma / w0^2 = c / k = 0.1 s for the default
// spring. Below the limit no row may be flagged diverged; the coarsest row (dt = 0.3125 s,
// |1 + h lambda| = 1.29, grown 1.29^32 ~ 3e3 times) must be.
TEST(sweep, divergence_follows_the_stability_limit) {
  const auto& ps = find(default_study(), "damped_spring");
  for (const auto& is : ps.integrators) {
    if (is.info.name != "euler") continue;
    EXPECT_TRUE(is.rows.front().metrics.diverged);
    for (const auto& row : is.rows) {
      if (row.dt < 0.1) {
        EXPECT_FALSE(row.metrics.diverged) << "dt " << row.dt;
      }
    }
  }
  // No stable method diverges anywhere on the default problems.
  for (const auto& p : default_study().problems) {
    for (const auto& is : p.integrators) {
      if (is.info.name == "euler") continue;
      for (const auto& row : is.rows) EXPECT_FALSE(row.metrics.diverged) << p.problem->name() << "/" << is.info.name;
    }
  }
}

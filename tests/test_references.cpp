// Tests of the GSL and CVODE reference solvers against closed forms, of their counters,
// and of their behaviour on bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "references/reference.hpp"

namespace stepbench {
namespace {

// x'' = -w^2 x - c x' + force(t), as y = [x, v].
ode_system oscillator(double w2, double c, double x0, double v0, double (*force)(double) = nullptr) {
  ode_system sys;
  sys.n = 2;
  sys.y0 = {x0, v0};
  sys.rhs = [w2, c, force](double t, std::span<const double> y, std::span<double> dydt) {
    dydt[0] = y[1];
    dydt[1] = -w2 * y[0] - c * y[1] + (force ? force(t) : 0.0);
  };
  return sys;
}

constexpr double w_undamped = 3.0;
ode_system undamped() { return oscillator(w_undamped * w_undamped, 0.0, 1.0, 0.5); }
double undamped_x(double t) { return std::cos(w_undamped * t) + 0.5 / w_undamped * std::sin(w_undamped * t); }

const double wd = std::sqrt(10.0 - 0.25);
ode_system damped() { return oscillator(10.0, 1.0, 1.0, 0.0); }
double damped_x(double t) { return std::exp(-t / 2) * (std::cos(wd * t) + 0.5 / wd * std::sin(wd * t)); }

// A force switched on at t = 5.05: steps across the jump fail the error test, so the counter
// identity below is exercised with failed_steps > 0.
ode_system kicked() {
  return oscillator(1.0, 0.0, 1.0, 0.0, [](double t) { return t > 5.05 ? 50.0 : 0.0; });
}

// 32 output times over (0, 10].
std::vector<double> output_times(int count = 32, double t_end = 10.0) {
  std::vector<double> ts;
  for (int i = 1; i <= count; ++i) ts.push_back(t_end * i / count);
  return ts;
}

class reference_source : public ::testing::TestWithParam<const char*> {};

INSTANTIATE_TEST_SUITE_P(all, reference_source, ::testing::ValuesIn(reference_sources),
                         [](const auto& info) { return std::string(info.param); });

void expect_closed_form(const reference_solution& sol, double (*x_exact)(double), double amplitude) {
  ASSERT_EQ(sol.y.size(), sol.times.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < sol.times.size(); ++i) {
    const double err = std::abs(sol.y[i][0] - x_exact(sol.times[i])) / amplitude;
    EXPECT_LT(err, 1e-9) << sol.source << " at t=" << sol.times[i];
    worst = std::max(worst, err);
  }
  std::cout << "  " << sol.source << ": max |x - x_exact| / amplitude = " << worst << "\n";
}

TEST_P(reference_source, matches_closed_form_undamped) {
  const auto ts = output_times();
  const auto sol = solve_reference(GetParam(), undamped(), ts);
  EXPECT_EQ(sol.source, GetParam());
  EXPECT_EQ(sol.times, ts);
  expect_closed_form(sol, undamped_x, std::hypot(1.0, 0.5 / w_undamped));
}

TEST_P(reference_source, matches_closed_form_damped) {
  // max |x| over t >= 0 is x(0) = 1: the envelope e^{-t/2} sqrt(1 + (1/2 / wd)^2) drops below 1
  // before the first crest after t = 0.
  const auto sol = solve_reference(GetParam(), damped(), output_times());
  expect_closed_form(sol, damped_x, 1.0);
}

TEST_P(reference_source, counters_are_consistent) {
  for (const auto& sys : {undamped(), damped(), kicked()}) {
    const auto s = solve_reference(GetParam(), sys, output_times()).stats;
    EXPECT_GT(s.rhs_evals_counted, 0);
    EXPECT_GT(s.steps, 0);
    EXPECT_EQ(s.rtol, reference_tolerances{}.rtol);
    EXPECT_EQ(s.atol, reference_tolerances{}.atol);
    EXPECT_GT(s.wall_seconds, 0.0);
    const std::string src = GetParam();
    if (src == "cvode_bdf") {
      // CVodeGetNumRhsEvals leaves out the n calls per difference-quotient Jacobian, which
      // CVodeGetNumLinRhsEvals counts: together they are every call.
      EXPECT_GT(s.lin_rhs_evals, 0);
      EXPECT_GT(s.jac_evals, 0);
      EXPECT_EQ(s.lin_rhs_evals, 2 * s.jac_evals);  // dense DQ Jacobian: one call per column, n = 2
      EXPECT_EQ(s.rhs_evals_counted, s.rhs_evals + s.lin_rhs_evals);
    } else if (src == "cvode_adams") {
      EXPECT_EQ(s.lin_rhs_evals, 0);
      EXPECT_EQ(s.jac_evals, 0);
      EXPECT_EQ(s.rhs_evals_counted, s.rhs_evals);
    } else {
      EXPECT_EQ(s.rhs_evals, s.rhs_evals_counted);
    }
  }
}

// GSL 2.7.1, ode-initval2/evolve.c and rk8pd.c: rk8pd declares can_use_dydt_in and
// gives_exact_dydt_out, and gsl_odeiv2_evolve_apply evaluates dydt_in only while its attempt
// counter is 0; afterwards it copies dydt_out of the last accepted step (first same as last).
// Every attempt, accepted or rejected, copies k1 from dydt_in and makes 12 stage calls
// (k2..k13) plus 1 for dydt_out, which is evaluated before the error test. No call is made
// per driver_apply. Hence, over a whole solve,
//   calls = 1 + 13 * (accepted + rejected attempts).
// (An older evolve.c, before the dydt_out reuse, would give steps + 13 * attempts: measured
// here it does not hold, e.g. 1119 calls for 56 accepted and 30 rejected, = 1 + 13 * 86.)
TEST(gsl_rk8pd, rhs_call_identity) {
  long total_failed = 0;
  for (const auto& sys : {undamped(), damped(), kicked()}) {
    for (const reference_tolerances tol :
         {reference_tolerances{}, reference_tolerances{1e-8, 1e-10}, reference_tolerances{1e-5, 1e-7}}) {
      const auto s = solve_gsl(sys, output_times(), gsl_method::rk8pd, tol).stats;
      EXPECT_EQ(s.rhs_evals_counted, 1 + 13 * (s.steps + s.failed_steps))
          << "rtol " << tol.rtol << ": steps " << s.steps << ", failed " << s.failed_steps;
      std::cout << "  rtol " << tol.rtol << ": steps " << s.steps << ", failed " << s.failed_steps << ", calls "
                << s.rhs_evals_counted << "\n";
      total_failed += s.failed_steps;
    }
  }
  EXPECT_GT(total_failed, 0) << "the identity was never exercised with a rejected step";
}

TEST(references, kicked_problem_rejects_steps) {
  for (const char* src : reference_sources) {
    const auto s = solve_reference(src, kicked(), output_times()).stats;
    EXPECT_GT(s.failed_steps, 0) << src;
  }
}

// An rhs that turns NaN at t > 4: no reference may return NaN, and none may crash.
TEST_P(reference_source, nan_rhs_throws_runtime_error) {
  auto sys = undamped();
  auto inner = sys.rhs;
  sys.rhs = [inner](double t, std::span<const double> y, std::span<double> dydt) {
    inner(t, y, dydt);
    if (t > 4.0) dydt[1] = std::numeric_limits<double>::quiet_NaN();
  };
  try {
    solve_reference(GetParam(), sys, output_times());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
    std::cout << "  " << e.what() << "\n";
  }
}

struct rhs_failure : std::exception {
  const char* what() const noexcept override { return "rhs_failure"; }
};

// The exception thrown by f crosses no C frame: it is caught in the callback and rethrown.
TEST_P(reference_source, rhs_exception_propagates) {
  auto sys = damped();
  auto inner = sys.rhs;
  sys.rhs = [inner](double t, std::span<const double> y, std::span<double> dydt) {
    if (t > 2.0) throw rhs_failure{};
    inner(t, y, dydt);
  };
  EXPECT_THROW(solve_reference(GetParam(), sys, output_times()), rhs_failure);
  // And at the very first call, before any step.
  sys.rhs = [](double, std::span<const double>, std::span<double>) { throw rhs_failure{}; };
  EXPECT_THROW(solve_reference(GetParam(), sys, output_times()), rhs_failure);
}

TEST_P(reference_source, rejects_bad_input) {
  const auto sys = damped();
  const std::vector<double> not_increasing{1.0, 2.0, 2.0, 3.0};
  const std::vector<double> decreasing{1.0, 3.0, 2.0};
  const std::vector<double> with_zero{0.0, 1.0};
  const std::vector<double> with_nan{1.0, std::numeric_limits<double>::quiet_NaN()};
  const std::vector<double> none;
  for (const auto* ts : {&not_increasing, &decreasing, &with_zero, &with_nan, &none})
    EXPECT_THROW(solve_reference(GetParam(), sys, *ts), std::invalid_argument);

  const auto ts = output_times();
  auto bad = sys;
  bad.y0 = {1.0};
  EXPECT_THROW(solve_reference(GetParam(), bad, ts), std::invalid_argument);
  bad = sys;
  bad.n = 0;
  bad.y0.clear();
  EXPECT_THROW(solve_reference(GetParam(), bad, ts), std::invalid_argument);
  bad = sys;
  bad.rhs = nullptr;
  EXPECT_THROW(solve_reference(GetParam(), bad, ts), std::invalid_argument);
  EXPECT_THROW(solve_reference(GetParam(), sys, ts, {-1e-10, 1e-12}), std::invalid_argument);
}

TEST(references, unknown_source_throws) {
  EXPECT_THROW(solve_reference("rk45", damped(), output_times()), std::invalid_argument);
  EXPECT_THROW(solve_reference("", damped(), output_times()), std::invalid_argument);
}

TEST(references, cost_is_sane_on_damped_oscillator) {
  const auto ts = output_times();
  for (const char* src : reference_sources) {
    const auto s = solve_reference(src, damped(), ts).stats;
    std::cout << "  " << src << ": steps " << s.steps << ", failed " << s.failed_steps << ", rhs_evals " << s.rhs_evals
              << ", lin_rhs_evals " << s.lin_rhs_evals << ", jac_evals " << s.jac_evals << ", rhs_evals_counted "
              << s.rhs_evals_counted << ", wall " << s.wall_seconds << " s\n";
    const std::string name = src;
    EXPECT_LT(s.steps, name == "gsl_rk8pd" ? 20'000 : 100'000) << name;
  }
}

}  // namespace
}  // namespace stepbench

// The step-size controller (integrators/step_control.hpp) on the error model of a linear
// test problem: for y' = lambda y, a step of h with an error estimate of order q makes
// err(h) = C h^(q+1) asymptotically, so the controller's steps follow from its formula in
// closed form. The elementary controller (beta = 0) lands on the step whose error is
// safety^(q+1) in one accepted step; Gustafsson's PI controller (beta > 0) converges to
// err* = safety^(1/(1/(q+1) - 1.75 beta)), its log-error deviation contracting by the
// dominant root of r^2 = a r + b, a = 0.75 (q+1) beta, b = (q+1) beta (HNW I, sec. IV.2;
// HNW II, sec. IV.2, "PI step size control").
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "integrators/step_control.hpp"

namespace stepbench {
namespace {

// The error a step of h makes on the model: C h^(q+1).
struct error_model {
  double c;
  int q;
  double operator()(double h) const { return c * std::pow(h, q + 1); }
};

// The accepted steps' errors from h0 on, n of them (rejections retried as the controller says).
std::vector<double> accepted_errors(step_controller control, const error_model& err, double h0, int n) {
  std::vector<double> out;
  double h = h0;
  while (static_cast<int>(out.size()) < n) {
    const double e = err(h);
    if (e <= 1.0) out.push_back(e);
    h = control.next(h, e);
  }
  return out;
}

TEST(step_control, elementary_controller_lands_on_the_target_error_in_one_step) {
  for (const auto form : {step_controller::rounding::product, step_controller::rounding::quotient})
    for (int q : {4, 7}) {
      step_controller control{.error_order = q, .form = form};
      const error_model err{1e6, q};
      // A first step with error 0.01 (accepted), then the fixed point: err = safety^(q+1).
      const double h0 = std::pow(0.01 / err.c, 1.0 / (q + 1));
      const double h1 = control.next(h0, err(h0));
      EXPECT_NEAR(h1 / h0, 0.9 * std::pow(0.01, -1.0 / (q + 1)), 1e-14);
      EXPECT_NEAR(err(h1), std::pow(0.9, q + 1), 1e-13) << q;
      const double h2 = control.next(h1, err(h1));
      EXPECT_NEAR(h2 / h1, 1.0, 1e-13) << q;
    }
}

TEST(step_control, a_rejection_shrinks_the_step_and_the_next_may_not_grow) {
  step_controller control{.error_order = 4, .beta = 0.04};
  const double h = 0.1;
  // err = 32: rejected, h scaled by safety 32^(-1/5) = 0.45.
  const double h_retry = control.next(h, 32.0);
  EXPECT_NEAR(h_retry / h, 0.45, 1e-15);
  // An accepted step right after a rejection does not grow, however small its error.
  EXPECT_EQ(control.next(h_retry, 1e-8), h_retry);
  // A step that blew up (NaN) is a rejection by the smallest factor.
  EXPECT_NEAR(control.next(h, std::nan("")) / h, 0.2, 1e-15);
  // A huge error is clamped at the smallest factor too; a zero one (no rejection before) at the largest.
  EXPECT_NEAR(step_controller{.error_order = 4}.next(h, 1e12) / h, 0.2, 1e-15);
  EXPECT_NEAR(step_controller{.error_order = 4}.next(h, 0.0) / h, 10.0, 1e-15);
}

TEST(step_control, pi_controller_converges_to_its_fixed_point_at_the_predicted_rate) {
  // dopri5.f's beta = 0.04 on a 5(4) pair (q = 4), and Verner's 2 / (5 p) for p = 7 (q = 6).
  for (const auto& [q, beta] : {std::pair{4, 0.04}, std::pair{6, 2.0 / 35.0}}) {
    step_controller control{.error_order = q, .beta = beta};
    const double e = 1.0 / (q + 1);
    const double fixed = std::pow(0.9, 1.0 / (e - 1.75 * beta));
    // Start well off the fixed point (an accepted error of 1e-6) and follow the log-error deviation.
    const error_model err{1.0, q};
    const auto errs = accepted_errors(control, err, std::pow(1e-6, e), 40);
    std::vector<double> dev;
    for (double x : errs) dev.push_back(std::log(x / fixed));
    EXPECT_LT(std::abs(dev.back()), 1e-3 * std::abs(dev.front())) << q;
    // The deviation follows d_{n+1} = a d_n + b d_{n-1} (the formula's logarithm, no clamp
    // active past the first steps): its ratio tends to the dominant root.
    const double a = 0.75 * (q + 1) * beta, b = (q + 1) * beta;
    const double root = (a + std::sqrt(a * a + 4 * b)) / 2;
    for (std::size_t n = 3; n < 30; ++n) EXPECT_NEAR(dev[n + 1], a * dev[n] + b * dev[n - 1], 1e-12) << q << " " << n;
    EXPECT_NEAR(dev[30] / dev[29], root, 1e-3) << q;
  }
}

}  // namespace
}  // namespace stepbench

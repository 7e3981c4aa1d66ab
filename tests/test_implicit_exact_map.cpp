// The implicit methods' errors are the methods', not their Newton solver's: on
// falling_drag, the pendulum and the damped spring, at every level of the study's dt
// ladder (32 to 65536 steps a horizon), implicit_euler and implicit_midpoint as the
// registry runs them agree with the exact map of each method, computed here
// independently: the same relations, written out for each problem's force in long
// double, each step's equation solved by Newton's method until the update vanishes
// (or stops decreasing) in long double.
//   implicit Euler:     v1 = v0 + h a(x0 + h v1, v1),   x1 = x0 + h v1
//   implicit midpoint:  vm = v0 + (h/2) a(x0 + (h/2) vm, vm),   x1 = x0 + h vm,   v1 = 2 vm - v0
// Asserted: the final state to 1e-13 of the motion's scale (2e-13 at 65536 steps, below),
// and err_pos_max (the study's
// position error, the largest over the 32 sample times j T / 32, against the closed form)
// within 1 % of the exact map's wherever the map's error is above round-off.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "registry/registry.hpp"

using namespace stepbench;

namespace {

using real = long double;

double param(const problem_instance& p, const std::string& name) {
  for (const auto& q : p.params())
    if (q.name == name) return q.value;
  throw std::invalid_argument("no parameter " + name);
}

// The acceleration a(x, v) of each scene, written from its force law (problems/*.hpp).
std::function<real(real, real)> acceleration(const problem_instance& p) {
  const std::string name(p.name());
  if (name == "falling_drag") {
    const real g = param(p, "gravity"), c_over_m = static_cast<real>(param(p, "drag")) / param(p, "mass_kg");
    return [=](real, real v) { return g - c_over_m * std::fabs(v) * v; };  // m g - c |v| v
  }
  if (name == "pendulum") {
    const real g_over_l = static_cast<real>(param(p, "gravity")) / param(p, "length_m");
    return [=](real x, real) { return -g_over_l * std::sin(x); };  // theta'' = -(g/L) sin theta
  }
  if (name == "damped_spring") {
    const real m = param(p, "mass_kg"), k = param(p, "k_s"), c = param(p, "k_d");
    return [=](real x, real v) { return -(k / m) * x - (c / m) * v; };  // m x'' = -k x - c v
  }
  throw std::invalid_argument("no acceleration for " + name);
}

// Solves v1 = v0 + h a(x0 + h v1, v1) for v1 by Newton's method in long double, the
// derivative by a central difference (exact enough for a Newton direction; the root is
// what the update's vanishing certifies), from v0.
real backward_euler_velocity(const std::function<real(real, real)>& a, real x0, real v0, real h) {
  auto r = [&](real v1) { return v1 - v0 - h * a(x0 + h * v1, v1); };
  real v1 = v0, last = INFINITY;
  for (int k = 0; k < 200; ++k) {
    const real d = 1e-7L * (1.0L + std::fabs(v1));
    const real slope = (r(v1 + d) - r(v1 - d)) / (2.0L * d);
    const real update = -r(v1) / slope;
    v1 += update;
    if (update == 0.0L || (std::fabs(update) >= last && last < 1e-12L * (1.0L + std::fabs(v1)))) break;
    last = std::fabs(update);
  }
  return v1;
}

struct map_run {
  std::vector<real> x_at_samples;
  real x_final = 0, v_final = 0;
};

// The exact map of the method over the fixed-step loop's grid (core/drive.hpp: steps of
// dt, the last one landing on the horizon), recording at the grid steps j n / samples.
map_run exact_map(const problem_instance& p, const std::string& method, long n, int samples) {
  const auto a = acceleration(p);
  const double horizon = p.horizon(), dt = horizon / static_cast<double>(n);
  const auto y0 = p.initial();
  real x = y0[0], v = y0[1];
  map_run out;
  double t = 0.0;
  for (long i = 0; i < n; ++i) {
    const double t_next = time_after_step(i + 1, n, dt, horizon);
    const real h = i + 1 == n ? static_cast<real>(horizon - t) : static_cast<real>(dt);
    if (method == "implicit_euler") {
      v = backward_euler_velocity(a, x, v, h);
      x += h * v;
    } else {
      const real vm = backward_euler_velocity(a, x, v, h / 2);
      x += h * vm;
      v = 2 * vm - v;
    }
    t = t_next;
    if ((i + 1) % (n / samples) == 0) out.x_at_samples.push_back(x);
  }
  out.x_final = x;
  out.v_final = v;
  return out;
}

class implicit_exact_map : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(implicit_exact_map, agrees_with_the_method_solved_to_round_off) {
  const auto& [problem, method] = GetParam();
  const auto p = make_problem(problem);
  constexpr int samples = 32;  // the study's sample times j T / 32 (study/sweep.hpp)
  const double horizon = p->horizon();
  const std::vector<double> times = sample_times(horizon, samples);
  std::vector<std::vector<double>> truth;
  double x_scale = std::abs(p->initial()[0]), v_scale = std::abs(p->initial()[1]);
  for (double t : times) {
    truth.push_back(p->exact(t));
    x_scale = std::max(x_scale, std::abs(truth.back()[0]));
    v_scale = std::max(v_scale, std::abs(truth.back()[1]));
  }
  int compared = 0;
  for (long n = 32; n <= 65536; n *= 2) {
    const double dt = horizon / static_cast<double>(n);
    const run_result run = p->run(method, dt, horizon, times, run_limits{});
    ASSERT_TRUE(run.stop_reason.empty()) << problem << "/" << method << " at " << n << " steps: " << run.stop_reason;
    const map_run map = exact_map(*p, method, n, samples);
    const int d = p->dim();
    // 1e-13 of the motion's scale; beyond 16384 steps the step's own rounding (a random
    // walk of the double-precision updates, which the pendulum's amplitude-dependent
    // period turns into phase) grows as sqrt(n): 2e-13 at 65536 steps.
    const double agree = 1e-13 * std::max(1.0, std::sqrt(static_cast<double>(n) / 16384.0));
    EXPECT_NEAR(run.final_y[0], static_cast<double>(map.x_final), agree * x_scale)
        << problem << "/" << method << " at " << n << " steps: final position";
    EXPECT_NEAR(run.final_y[d], static_cast<double>(map.v_final), agree * v_scale)
        << problem << "/" << method << " at " << n << " steps: final velocity";
    double err_run = 0.0, err_map = 0.0;
    for (std::size_t j = 0; j < times.size(); ++j) {
      err_run = std::max(err_run, std::abs(run.sample_y[j][0] - truth[j][0]));
      err_map = std::max(err_map, static_cast<double>(std::fabs(map.x_at_samples[j] - truth[j][0])));
    }
    if (err_map > 1e-12 * x_scale) {  // above round-off
      EXPECT_NEAR(err_run, err_map, 0.01 * err_map) << problem << "/" << method << " at " << n << " steps: err_pos_max "
                                                    << err_run << ", the exact map's " << err_map;
      ++compared;
    }
  }
  EXPECT_GE(compared, 6) << "levels with an error above round-off";
}

INSTANTIATE_TEST_SUITE_P(methods, implicit_exact_map,
                         ::testing::Combine(::testing::Values("falling_drag", "pendulum", "damped_spring"),
                                            ::testing::Values("implicit_euler", "implicit_midpoint")),
                         [](const auto& info) { return std::get<0>(info.param) + "_" + std::get<1>(info.param); });

}  // namespace

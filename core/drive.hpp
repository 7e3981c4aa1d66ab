#pragma once
// The fixed-step loop: advances a problem from t = 0 to the horizon with one
// integrator, counting force evaluations and recording the state at chosen steps.
// Instantiated per (problem, integrator); everything inside the loop inlines.
#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "core/concepts.hpp"

namespace stepbench {

// Steps needed to reach `horizon` with `dt`: ceil(horizon / dt), with a relative slack
// of 1e-12 so that a horizon that is a whole number of steps up to rounding does not
// get an extra sliver of a step. The last step is shortened to land exactly on the
// horizon when horizon / dt is not whole.
inline long steps_for(double horizon, double dt) {
  return std::max(1L, static_cast<long>(std::ceil(horizon / dt * (1.0 - 1e-12))));
}

// Time after step i of n (i = n is exactly the horizon).
inline double time_after_step(long i, long n, double dt, double horizon) {
  return i == n ? horizon : static_cast<double>(i) * dt;
}

// The steps at which a run is measured: the steps nearest to the fixed fractions
// j / sample_count of the horizon, j = 1..sample_count (fewer when the run has fewer
// steps). On the sweep's ladder every level has a multiple of sample_count steps, so
// these are the same times t_j = j T / sample_count at every level.
inline std::vector<long> sample_steps(double horizon, double dt, int sample_count) {
  const long n = steps_for(horizon, dt);
  std::vector<long> out;
  for (int j = 1; j <= sample_count; ++j) {
    const double t = horizon * j / sample_count;
    long i = j == sample_count ? n : std::clamp(std::lround(t / dt), 1L, n);
    if (out.empty() || i > out.back()) out.push_back(i);
  }
  return out;
}

// y' = [v; F / m] for first-order solvers (the references, the first-order peers), with
// the same arithmetic as the step loop: the force model times 1 / m computed once.
template <problem P>
inline void first_order_rhs(const P& p, double inv_mass, double t, const double* y, double* dydt) {
  using vec = typename P::vec;
  vec x(P::dim), v(P::dim);
  for (int i = 0; i < P::dim; ++i) x[i] = y[i], v[i] = y[P::dim + i];
  const vec a = p.force(t, x, v) * inv_mass;
  for (int i = 0; i < P::dim; ++i) dydt[i] = v[i], dydt[P::dim + i] = a[i];
}

// Counts force evaluations; the integrators see it as the problem.
template <class P>
struct counted_system {
  const P& problem;
  double inv_mass = 1.0 / problem.mass();
  mutable long evals = 0;
  static constexpr bool force_depends_on_velocity = P::force_depends_on_velocity;
  double mass() const { return problem.mass(); }
  double inverse_mass() const { return inv_mass; }
  typename P::vec force(double t, const typename P::vec& x, const typename P::vec& v) const {
    ++evals;
    return problem.force(t, x, v);
  }
};

template <class Vec>
struct drive_result {
  long steps = 0;        // steps taken (fewer than planned when the run diverged)
  long force_evals = 0;
  bool non_finite = false;  // a NaN or Inf appeared: the run stopped there
  std::vector<double> sample_t;
  std::vector<phase<Vec>> samples;  // state after each sampled step
  double t_final = 0.0;
  phase<Vec> final_state;
};

template <class Vec>
inline bool all_finite(const step_state<Vec>& s) {
  return s.x.allFinite() && s.v.allFinite();
}

// Integrates `problem` to `horizon` with steps of `dt`; records the state after each
// step listed in `record_steps` (increasing). A non-finite state stops the run.
// flatten: everything called from the loop (the step, the force model, Eigen's
// expression templates) is inlined into it whatever the optimisation level; at -O2 GCC's
// inliner otherwise stops a few calls deep and a step costs ~1.8x more.
template <problem P, integrator I>
[[gnu::flatten]] drive_result<typename P::vec> drive(const P& problem, I method, double dt, double horizon,
                                    std::span<const long> record_steps) {
  using Vec = typename P::vec;
  counted_system<P> sys{problem};
  const phase<Vec> start = problem.initial();
  step_state<Vec> s{start.x, start.v, Vec::Zero(start.x.size()), false};
  const long n = steps_for(horizon, dt);

  drive_result<Vec> out;
  out.sample_t.reserve(record_steps.size());
  out.samples.reserve(record_steps.size());
  auto next = record_steps.begin();
  long i = 0;
  double t = 0.0;
  while (i < n) {
    // Every step is exactly dt except a shortened last one; t itself is i * dt, not
    // a running sum, so it carries no accumulated rounding.
    const double t_next = time_after_step(i + 1, n, dt, horizon);
    method.step(sys, t, s, i + 1 == n ? horizon - t : dt);
    ++i;
    t = t_next;
    if (next != record_steps.end() && *next == i) {
      ++next;
      if (!all_finite(s)) {
        out.non_finite = true;
        break;
      }
      out.sample_t.push_back(t);
      out.samples.push_back({s.x, s.v});
    }
  }
  out.non_finite = out.non_finite || !all_finite(s);
  out.steps = i;
  out.force_evals = sys.evals;
  out.t_final = t;
  out.final_state = {s.x, s.v};
  return out;
}

}  // namespace stepbench

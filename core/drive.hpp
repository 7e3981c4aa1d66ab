#pragma once
// The drive loops: advance a problem from t = 0 to the horizon with one integrator,
// counting the work and recording the state at chosen times. Instantiated per
// (problem, integrator); everything inside a loop inlines.
//
// Every loop runs the same named stages per step, as Box2D names its solver stages:
//   advance     the integrator's step (or an adaptive attempt, repeated until accepted);
//               in `locate` contact mode it also finds a contact inside the step, steps
//               to it, resolves it and finishes the step
//   after_step  in `end_of_step` contact mode the contacts are resolved here; a changed
//               state clears the cached force
//   record      the state at a requested time: reached by the step (fixed grid), by
//               shortening a step to land on it, or from the method's dense output
// No integrator knows about contacts.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/concepts.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"
#include "core/system.hpp"

namespace stepbench {

// Steps needed to reach `horizon` with `dt`: ceil(horizon / dt), with a relative slack
// of 1e-12 so that a horizon that is a whole number of steps up to rounding does not
// get an extra sliver of a step. The last step is shortened to land exactly on the
// horizon when horizon / dt is not whole.
inline long steps_for(double horizon, double dt) {
  return std::max(1L, static_cast<long>(std::ceil(horizon / dt * (1.0 - 1e-12))));
}

// Time after step i of n on the grid (i = n is exactly the horizon). t is i dt, not a
// running sum, so it carries no accumulated rounding.
inline double time_after_step(long i, long n, double dt, double horizon) {
  return i == n ? horizon : static_cast<double>(i) * dt;
}

// Where a fixed-step run records. A time on the grid (within 1e-9 dt of i dt, or the
// horizon) is reached by step `step`; a time off the grid lies inside step `step`,
// which the loop splits to land on it (as it shortens the last step for the horizon).
struct record_point {
  double t = 0.0;
  long step = 0;
  bool on_grid = true;
};

// The plan for `times` (increasing, in (0, horizon]). Throws std::invalid_argument
// otherwise.
std::vector<record_point> plan_records(double horizon, double dt, std::span<const double> times);

// The grid times nearest to the fixed fractions j / count of the horizon, j = 1..count
// (fewer when the run has fewer steps): what `stepbench run` records at any dt, so the
// run itself is not changed by where it is measured. On the sweep's ladder every level
// has a multiple of count steps, so these are the times j T / count at every level.
std::vector<double> nearest_grid_times(double horizon, double dt, int count);

// The fractions j T / count, j = 1..count (the last exactly T).
std::vector<double> sample_times(double horizon, int count);

// A run as the loop records it (core/method.hpp's run_record), with its states in the
// loop's own form.
template <class Vec>
struct drive_result : run_record {
  Eigen::MatrixXd samples;  // column j: [x; v] at sample_t[j]
  double t_final = 0.0;
  phase<Vec> final_state;

  // Contacts (problems with contacts only; core/concepts.hpp's has_contacts).
  static constexpr std::size_t recorded_contacts = 64;  // the first ones are recorded with their time
  static constexpr int contact_position_dims = 4;       // ... and their position, up to this many coordinates
  Eigen::MatrixXd contact_x;  // column k: the position just after contact k (empty for larger states)

  // Sizes everything a run records, once: no step allocates.
  void start(int dim, std::size_t count) {
    contact_times.reserve(recorded_contacts);
    if (dim <= contact_position_dims) contact_x.resize(dim, static_cast<Eigen::Index>(recorded_contacts));
    sample_t.reserve(count);
    samples.resize(2 * dim, static_cast<Eigen::Index>(count));
  }

  // A resolution at t that left the position x: every contact it resolved is counted
  // (several at once share the time).
  template <class X>
  void contact(double t, const contact_outcome& c, const Eigen::MatrixBase<X>& x) {
    tunnelled += c.tunnelled;
    max_penetration = std::max(max_penetration, c.depth);
    for (int k = 0; k < c.resolved; ++k, ++contacts) {
      if (contact_times.size() >= recorded_contacts) continue;
      if (contact_x.size() > 0) contact_x.col(static_cast<Eigen::Index>(contact_times.size())) = x;
      contact_times.push_back(t);
    }
  }

  template <class X, class V>
  void record(double t, const Eigen::MatrixBase<X>& x, const Eigen::MatrixBase<V>& v) {
    const auto j = static_cast<Eigen::Index>(sample_t.size());
    const auto d = x.size();
    // Coordinate by coordinate: GCC 12 misreads Eigen's packet copy from a Map of the
    // second half of a peer's two-coordinate std::array state as reading past it
    // (-Wstringop-overread); the copy is exact either way.
    double* col = samples.col(j).data();
    for (Eigen::Index i = 0; i < d; ++i) col[i] = x[i], col[d + i] = v[i];
    sample_t.push_back(t);
  }
};

inline std::string fmt_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

template <class Vec>
inline bool all_finite(const Vec& x, const Vec& v) {
  return x.allFinite() && v.allFinite();
}

// The adaptive loops' stops (ours below, the peers' in core/step_adapter.hpp). A step of h
// from t lost in the round-off of t stops the run with a recorded failure.
template <class Vec>
inline bool stop_on_underflow(drive_result<Vec>& out, double h, double t, double horizon) {
  if (h > 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(t), horizon)) return false;
  out_of_line([&] { out.stop_reason = "step size underflow at t = " + std::to_string(t); });
  return true;
}
// A run that has taken its `max_steps` accepted steps short of the horizon is stopped as
// over budget: skipped, not failed.
template <class Vec>
inline bool stop_at_step_budget(drive_result<Vec>& out, long max_steps, double t, double horizon) {
  if (out.steps < max_steps || !(t < horizon)) return false;
  out_of_line([&] {
    out.skipped = true;
    out.stop_reason = "over the step budget of " + std::to_string(max_steps) + " steps at t = " + std::to_string(t);
  });
  return true;
}

// Stage after_step: in end_of_step mode the problem's contacts. A state they change
// invalidates the cached force. Returns what the contact resolution did.
template <problem P, class Vec>
inline contact_outcome after_step(const P& problem, double t, step_state<Vec>& s) {
  if constexpr (has_contacts<P>) {
    if (!problem.locate_contacts()) {
      const contact_outcome c = problem.resolve_contacts(t, s.x, s.v);
      if (c.changed) s.f_current = false;
      return c;
    }
  }
  return {};
}

// Resolves the contacts at t (locate mode, at the located time) and records them.
template <problem P, class Vec>
inline void resolve_here(const P& problem, double t, step_state<Vec>& s, drive_result<Vec>& out) {
  if constexpr (has_contacts<P>) {
    const contact_outcome c = problem.resolve_contacts(t, s.x, s.v);
    if (c.changed) s.f_current = false;
    out.contact(t, c, s.x);
  }
}

// The Illinois variant of regula falsi (Dahlquist & Bjorck, Numerical Methods, sec.
// 6.2.2) on a gap with g(lo) > 0 >= g(hi), to |hi - lo| <= tol. Returns the contact point
// from the penetrated side (the response moves the body back to the surface): hi, or a
// point where the gap is exactly zero. `last` is the last point evaluated, so a caller
// whose state follows each evaluation knows whether it must evaluate the root again.
template <class Gap>
inline double illinois_contact(double lo, double hi, double g_lo, double g_hi, double tol, Gap&& gap, double& last) {
  int side = 0;
  last = hi;
  for (int k = 0; k < 100 && hi - lo > tol; ++k) {
    double x = lo + (hi - lo) * g_lo / (g_lo - g_hi);
    if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
    const double g = gap(x);
    last = x;
    if (g == 0.0) return x;
    if (g > 0.0) {
      lo = x, g_lo = g;
      if (side == -1) g_hi *= 0.5;
      side = -1;
    } else {
      hi = x, g_hi = g;
      if (side == 1) g_lo *= 0.5;
      side = 1;
    }
  }
  return hi;
}

// Stage advance in locate mode: steps from t by h; when the step ends penetrated, the
// contact time is found by the method's own step (re-stepping from the saved start
// with the Illinois variant of regula falsi on the gap, to 1e-12 of h), the state is
// stepped there, the contact resolved, and the rest of the step taken (which may meet
// another contact). Every re-step's force evaluations are counted. A ball coming to
// rest would meet contacts ever closer together (Zeno): after 64 contacts within one
// step the rest of it is taken with end-of-step resolution.
template <problem P, class Stepper, class Sys, class Vec>
inline void advance_locating(const P& problem, Stepper& stepper, const Sys& sys, double t, step_state<Vec>& s, double h,
                             step_state<Vec>& start, drive_result<Vec>& out) {
  double done = 0.0;
  for (int contacts = 0; done < h; ++contacts) {
    const double t0 = t + done, rest = h - done;
    start = s;
    stepper.step(sys, t0, s, rest);
    const double gap_end = problem.contact_gap(t0 + rest, s.x, s.v);
    if (!(gap_end < 0.0)) return;
    const double gap_start = problem.contact_gap(t0, start.x, start.v);
    if (!(gap_start > 0.0) || contacts >= 64) {
      // Already touching at the start (resting), or Zeno: resolve at the end of the step.
      resolve_here(problem, t0 + rest, s, out);
      return;
    }
    // The contact time: the root of g(tau) = the gap after a step of tau from the start.
    double last = rest;
    const double tau = illinois_contact(
        0.0, rest, gap_start, gap_end, 1e-12 * h,
        [&](double trial) {
          s = start;
          stepper.step(sys, t0, s, trial);
          return problem.contact_gap(t0 + trial, s.x, s.v);
        },
        last);
    if (last != tau) {
      s = start;
      stepper.step(sys, t0, s, tau);
    }
    resolve_here(problem, t0 + tau, s, out);
    done += tau;
  }
}

template <problem P>
inline step_state<typename P::vec> start_state(const P& problem) {
  using Vec = typename P::vec;
  const phase<Vec> start = problem.initial();
  return {start.x, start.v, Vec::Zero(start.x.size()), false};
}

// The fixed-step loop itself, shared by our drive loop and the peers' (which keep their
// state in their own form): steps of exactly dt but a shortened last one, split where a
// record time falls inside a step. `advance(t, h)` steps from t by h; `after_step(t)`
// runs the problem's hook; `record(t)` stores the state at t and returns false when the
// state is not finite, which stops the run. Returns the grid steps taken and the time
// reached.
struct loop_end {
  long steps = 0;
  double t = 0.0;
};
template <class Advance, class AfterStep, class Record>
[[gnu::always_inline]] inline loop_end fixed_step_loop(double dt, double horizon, std::span<const record_point> plan,
                                                       Advance&& advance, AfterStep&& after_step, Record&& record) {
  const long n = steps_for(horizon, dt);
  auto next = plan.begin();
  long i = 0;
  double t = 0.0;
  while (i < n) {
    double h = i + 1 == n ? horizon - t : dt;
    if (next != plan.end() && next->step == i + 1 && !next->on_grid) {
      // Record times inside this step: land on each (advance, after_step, record), then
      // finish the step to the grid point.
      do {
        advance(t, next->t - t);
        t = next->t;
        after_step(t);
        if (!record(t)) return {i, t};
        ++next;
      } while (next != plan.end() && next->step == i + 1 && !next->on_grid);
      h = time_after_step(i + 1, n, dt, horizon) - t;
    }
    // advance
    advance(t, h);
    ++i;
    t = time_after_step(i, n, dt, horizon);
    // after_step
    after_step(t);
    // record
    if (next != plan.end() && next->step == i) {
      ++next;
      if (!record(t)) return {i, t};
    }
  }
  return {i, t};
}

// Integrates `problem` to `horizon` with steps of `dt`, recording where `plan` says. A
// non-finite recorded state stops the run.
// flatten: everything called from the loop (the step, the force model, Eigen's
// expression templates) is inlined into it whatever the optimisation level; at -O2 GCC's
// inliner otherwise stops a few calls deep and a step costs ~1.8x more.
template <problem P, integrator I>
STEPBENCH_FLATTEN drive_result<typename P::vec> drive(const P& problem, const I& method, double dt, double horizon,
                                                      std::span<const record_point> plan) {
  using Vec = typename P::vec;
  counted_system<P> sys{problem};
  step_state<Vec> s = start_state(problem);
  stepper_t<I, counted_system<P>> stepper(method);
  prepare_stepper(stepper, sys, s.x);
  drive_result<Vec> out;
  out.start(problem.dim(), plan.size());
  step_state<Vec> start = s;  // the start of a step, for locating a contact inside it
  const loop_end end = fixed_step_loop(
      dt, horizon, plan,
      [&](double t, double h) {
        if constexpr (has_contacts<P>) {
          if (problem.locate_contacts()) return advance_locating(problem, stepper, sys, t, s, h, start, out);
        }
        if constexpr (has_scene_report<P>) {
          // A step that fails (an implicit method's Newton finds no root) leaves the state
          // where the step began: the reason opens with what the scene did there.
          try {
            stepper.step(sys, t, s, h);
          } catch (const std::runtime_error& e) {
            throw std::runtime_error(problem.scene_report(t, s.x, s.v) + "; then " + e.what());
          }
        } else {
          stepper.step(sys, t, s, h);
        }
      },
      [&](double t) { out.contact(t, stepbench::after_step(problem, t, s), s.x); },
      [&](double t) {
        if (!all_finite(s.x, s.v)) return out.non_finite = true, false;
        out.record(t, s.x, s.v);
        return true;
      });
  out.non_finite = out.non_finite || !all_finite(s.x, s.v);
  out.steps = end.steps;
  out.work = sys.work;
  out.t_final = end.t;
  out.final_state = {s.x, s.v};
  return out;
}

// Locate mode in the adaptive loop: a step that ends penetrated, from t_old to t_end,
// has its contact found on the method's dense output (Illinois on the gap of the
// interpolated state); the state is moved there and the rest of the step discarded (the
// next attempt starts from the contact). The bracket is the first sample of the dense
// output (16 a step) where the gap turns from positive to not: a step that starts from
// a contact (gap 0, moving away) and ends past the next one has no sign change between
// its ends alone. Returns the contact time (t_end when no sample bracketed one).
template <problem P, class Stepper, class Vec>
inline double locate_on_dense_output(const P& problem, Stepper& stepper, double t_old, double t_end, step_state<Vec>& s,
                                     Vec& x_dense, Vec& v_dense) {
  auto gap_at = [&](double theta) {
    stepper.interpolate(theta, x_dense, v_dense);
    return problem.contact_gap(t_old + theta * (t_end - t_old), x_dense, v_dense);
  };
  constexpr int samples = 16;
  double lo = 0.0, hi = 1.0, g_lo = gap_at(0.0), g_hi = problem.contact_gap(t_end, s.x, s.v);
  for (int j = 1; j <= samples; ++j) {
    const double theta_j = static_cast<double>(j) / samples;
    const double g = j == samples ? g_hi : gap_at(theta_j);
    if (g_lo > 0.0 && !(g > 0.0)) {
      hi = theta_j, g_hi = g;
      break;
    }
    lo = theta_j, g_lo = g;
  }
  if (!(g_lo > 0.0)) return t_end;
  double last = hi;
  const double theta = illinois_contact(lo, hi, g_lo, g_hi, 1e-12, gap_at, last);
  if (last != theta) stepper.interpolate(theta, x_dense, v_dense);
  s.x = x_dense;
  s.v = v_dense;
  s.f_current = false;
  return t_old + theta * (t_end - t_old);
}

// The adaptive loop. Steps are the method's own, shortened only to land on the horizon
// and, for a method without dense output, on each record time (a method with dense
// output interpolates the record times inside its steps instead). A run stops with a
// recorded failure when the step size falls below round-off of t, and is stopped as over
// budget (skipped, not failed) when it has taken `max_steps` accepted steps or when, at
// its present step size, the rest of the horizon would take more than ten times the
// steps left (a first-order method at a tight tolerance: its steps would have to be so
// small that the run could not finish, and often its error estimate would sink into
// round-off first).
template <problem P, adaptive_integrator I>
STEPBENCH_FLATTEN drive_result<typename P::vec> drive_adaptive(const P& problem, const I& method, double horizon,
                                                               std::span<const double> times, long max_steps) {
  using Vec = typename P::vec;
  counted_system<P> sys{problem};
  step_state<Vec> s = start_state(problem);
  stepper_t<I, counted_system<P>> stepper(method);
  prepare_stepper(stepper, sys, s.x);
  constexpr bool dense = dense_output_integrator<I>;

  drive_result<Vec> out;
  out.start(problem.dim(), times.size());
  Vec x_dense = s.x, v_dense = s.v;  // interpolated states (workspace)
  auto next = times.begin();
  double t = 0.0;
  double h = out_of_line([&] { return stepper.initial_dt(sys, t, s, horizon); });
  while (t < horizon) {
    const double target = dense || next == times.end() ? horizon : *next;
    // Land on the target when the proposed step reaches it or nearly does (a sliver of a
    // step left over would cost a whole step): Hairer's codes stretch by up to 1 %.
    const bool lands = t + 1.01 * h >= target;
    const double h_try = lands ? target - t : h;
    if (stop_on_underflow(out, h_try, t, horizon)) break;
    // advance: attempts until one is accepted
    const step_attempt a = stepper.try_step(sys, t, s, h_try);
    h = a.dt_next;
    if ((horizon - t) / h > 10.0 * static_cast<double>(max_steps - out.steps)) {
      out_of_line([&] {
        out.skipped = true;
        out.stop_reason = "over the step budget of " + std::to_string(max_steps) +
                          " steps: at t = " + std::to_string(t) + " the step size " + fmt_g(h) + " would need about " +
                          fmt_g((horizon - t) / h) + " more";
      });
      break;
    }
    if (!a.accepted) {
      ++out.rejected_steps;
      if (!std::isfinite(h)) {
        out.non_finite = true;
        break;
      }
      continue;
    }
    const double t_old = t;
    t = lands ? target : t + a.dt_taken;
    const double t_step_end = t;  // the end of the step the dense output covers
    ++out.steps;
    // locate: a contact inside the accepted step is found on the method's dense output
    // (locate_on_dense_output) and resolved there; a method without dense output resolves
    // at the end of its step, as end_of_step does.
    if constexpr (has_contacts<P>) {
      if (problem.locate_contacts() && problem.contact_gap(t, s.x, s.v) < 0.0) {
        if constexpr (dense)
          t = out_of_line(
              [&] { return locate_on_dense_output(problem, stepper, t_old, t_step_end, s, x_dense, v_dense); });
        resolve_here(problem, t, s, out);
      }
    }
    // after_step
    out.contact(t, after_step(problem, t, s), s.x);
    if (!all_finite(s.x, s.v)) {
      out.non_finite = true;
      break;
    }
    // record
    if constexpr (dense) {
      for (; next != times.end() && *next <= t; ++next) {
        if (*next == t) {
          out.record(t, s.x, s.v);
        } else {
          stepper.interpolate((*next - t_old) / (t_step_end - t_old), x_dense, v_dense);
          out.record(*next, x_dense, v_dense);
        }
      }
    } else {
      if (next != times.end() && t == *next) {
        out.record(t, s.x, s.v);
        ++next;
      }
    }
    if (stop_at_step_budget(out, max_steps, t, horizon)) break;
  }
  out.work = sys.work;
  out.t_final = t;
  out.final_state = {s.x, s.v};
  return out;
}

}  // namespace stepbench

#pragma once
// A peer is a descriptor and a step adapter; the loops here own everything else. As
// OrdinaryDiffEq.jl's integrator owns the loop while a method's perform_step! only steps,
// and GSL's evolve and driver stand apart from its step types: the adapter keeps the
// library's stepper and its state in the library's own form and takes one step (or one
// attempt); the loop lands on the record times and the horizon (core/drive.hpp's
// fixed-step loop), records the state, stops at a NaN or Inf, counts and finishes.
//
// A peer declares, in one struct:
//   static method_info describe();                the descriptor (core/method.hpp)
//   template <problem P> static constexpr bool applies;   optional: where it runs
//   template <problem P> struct adapter {          the step adapter for problem P
//     explicit adapter(const P&);                  fixed step: set up at the initial state
//     adapter(const P&, double tol);               adaptive: the same, at a tolerance
//     void step(double t, double h);               fixed step: advance from t by h
//     bool try_step(double& t, double& h);         adaptive: one attempt; on success t
//                                                  is advanced, h is the next step to try
//     template <class Vec> void state_into(Vec& x, Vec& v) const;  [x; v]
//     long force_evals() const;                    right-hand-side calls so far
//   };
// and is registered as fixed_step_peer<Peer> or adaptive_peer<Peer> (peers/all.hpp).
// The adapter is constructed in place and never copied (a library's callback holds its
// address).
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"

namespace stepbench::peers {

namespace adapter_detail {
// The positions an adapter draws where they are not its state's (xpbd's particles): a
// sample's, or where the run stopped.
template <class Adapter>
[[gnu::always_inline]] inline void record_drawn(run_record& out, const Adapter& a, bool final) {
  if constexpr (requires(std::vector<double> & y) { a.drawn_into(y); }) {
    std::vector<double>& y = final ? out.drawn_final : out.drawn_samples.emplace_back();
    a.drawn_into(y);
  }
}

// The state at t recorded; false (and the run marked non-finite) when it is not finite.
template <class Vec, class Adapter>
[[gnu::always_inline]] inline bool record_if_finite(drive_result<Vec>& out, const Adapter& a, double t, Vec& x,
                                                    Vec& v) {
  a.state_into(x, v);
  if (!all_finite(x, v)) return out.non_finite = true, false;
  out.record(t, x, v);
  record_drawn(out, a, false);
  return true;
}

// The end of a run: where it stopped, the final state and the work counted.
template <class Vec, class Adapter>
[[gnu::always_inline]] inline void finish(drive_result<Vec>& out, const Adapter& a, double t, Vec& x, Vec& v) {
  a.state_into(x, v);
  out.t_final = t;
  out.work.force_evals = a.force_evals();
  if constexpr (requires { a.constraint_violation(); }) out.constraint_violation = a.constraint_violation();
  out.non_finite = out.non_finite || !all_finite(x, v);
  out.final_state = {x, v};
  record_drawn(out, a, true);
}
}  // namespace adapter_detail

// What every peer entry declares: its descriptor with the kind of its loop, and where
// it runs.
template <class Peer, method_kind Kind>
struct peer_entry {
  static method_info info() {
    method_info m = Peer::describe();
    m.kind = Kind;
    return m;
  }
  template <problem P>
  static constexpr bool applies = method_applies<Peer, P>();
};

// A fixed-step peer at our dt, on core/drive.hpp's fixed-step loop (the same grid,
// landing and recording as our methods'). Flattened: the adapter's step inlines into the
// loop, as ours does into drive().
template <class Peer>
struct fixed_step_peer : peer_entry<Peer, method_kind::fixed_step> {
  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return run(p, dt, horizon, plan); };
  }

  template <problem P>
  STEPBENCH_FLATTEN static drive_result<typename P::vec> run(const P& p, double dt, double horizon,
                                                             std::span<const record_point> plan) {
    using Vec = typename P::vec;
    typename Peer::template adapter<P> a(p);
    Vec x(p.dim()), v(p.dim());
    drive_result<Vec> out;
    out.start(p.dim(), plan.size());
    const loop_end end = fixed_step_loop(
        dt, horizon, plan, [&](double t, double h) { a.step(t, h); }, [](double) {},
        [&](double t) { return adapter_detail::record_if_finite(out, a, t, x, v); });
    out.steps = end.steps;
    adapter_detail::finish(out, a, end.t, x, v);
    return out;
  }
};

// An adaptive peer over the tolerance ladder. The loop is Boost.Odeint's integrate_times
// (boost/numeric/odeint/integrate/detail/integrate_times.hpp, controlled-stepper
// version), written out so that rejected attempts and the step budget are counted: each
// step is shortened to land exactly on the next record time, and after a shortened step
// the step size before it is kept if larger. The first step is GSL's driver's (1e-6 of
// the first record time): the adapter's library needs one from the user. A run stops
// with a recorded failure when the step size falls below round-off of t, and is stopped
// as over budget (skipped, not failed) after the adaptive step budget (run_limits) for
// the peer's `evals_per_step`.
template <class Peer>
struct adaptive_peer : peer_entry<Peer, method_kind::adaptive> {
  template <problem P>
  static auto prepare(const P& p, double tol, double horizon, std::span<const double> times, const run_limits& limits) {
    const long max_steps = limits.adaptive_steps(p.dim(), Peer::evals_per_step);
    return [p, tol, horizon, max_steps, t = std::vector<double>(times.begin(), times.end())] {
      return run(p, tol, horizon, t, max_steps);
    };
  }

  template <problem P>
  STEPBENCH_FLATTEN static drive_result<typename P::vec> run(const P& p, double tol, double horizon,
                                                             std::span<const double> times, long max_steps) {
    using Vec = typename P::vec;
    typename Peer::template adapter<P> a(p, tol);
    Vec x(p.dim()), v(p.dim());
    drive_result<Vec> out;
    out.start(p.dim(), times.size());
    double t = 0.0, dt = 1e-6 * times.front();
    [&] {  // steps and records until the run ends or stops
      for (double tout : times) {
        while (t < tout) {
          double h = std::min(dt, tout - t);
          const bool lands = h == tout - t;
          if (stop_on_underflow(out, h, t, horizon)) return;
          double t_step = t;
          if (a.try_step(t_step, h)) {
            ++out.steps;
            t = lands ? tout : t_step;
            dt = std::max(dt, h);  // h now holds the proposed next step
            if (stop_at_step_budget(out, max_steps, t, horizon)) return;
          } else {
            ++out.rejected_steps;
            dt = h;
            if (!std::isfinite(dt)) {
              out.non_finite = true;
              return;
            }
          }
        }
        if (!adapter_detail::record_if_finite(out, a, t, x, v)) return;
      }
    }();
    adapter_detail::finish(out, a, t, x, v);
    return out;
  }
};

}  // namespace stepbench::peers

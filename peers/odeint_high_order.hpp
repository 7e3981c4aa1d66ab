#pragma once
// Boost.Odeint's high-order solvers, what a C++ user picks for tight accuracy, on
// std::array (problems with a fixed-size state; STEPBENCH_HAVE_ODEINT):
//  - adaptive, over the tolerance ladder (eps_abs = eps_rel = tol, Odeint's default error
//    checker): controlled runge_kutta_dopri5 (`odeint_dopri5_adaptive`), controlled
//    runge_kutta_fehlberg78 (`odeint_rkf78_adaptive`) and bulirsch_stoer
//    (`odeint_bulirsch_stoer`);
//  - runge_kutta_fehlberg78 at our dt (`odeint_rkf78`): the library's own eighth-order
//    step, for the step-cost comparison with rk8.
// The adaptive loop is integrate_times' (boost/numeric/odeint/integrate/detail/
// integrate_times.hpp, controlled-stepper version), written out so that rejected
// attempts and the step budget are counted: each step is shortened to land exactly on
// the next sample time, and after a shortened step the step size before it is kept if
// larger. The first step is GSL's driver's (1e-6 of the first sample time): Odeint
// needs one from the user.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"

#if STEPBENCH_HAVE_ODEINT
#include <boost/numeric/odeint/stepper/bulirsch_stoer.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#endif

namespace stepbench::peers {

#if STEPBENCH_HAVE_ODEINT
namespace odeint_detail {
namespace odeint = boost::numeric::odeint;

template <problem P>
inline constexpr bool fixed_size = P::vec::RowsAtCompileTime != Eigen::Dynamic;

template <problem P>
using state = std::array<double, 2 * P::vec::RowsAtCompileTime>;

template <problem P>
state<P> initial_state(const P& p) {
  constexpr int d = P::vec::RowsAtCompileTime;
  state<P> y;
  const auto s0 = p.initial();
  for (int i = 0; i < d; ++i) y[i] = s0.x[i], y[d + i] = s0.v[i];
  return y;
}

// (Copied coordinate by coordinate: GCC 12 misreads Eigen's packet copy from a Map of
// the second half of the std::array as reading past it, -Wstringop-overread.)
template <problem P>
void record(drive_result<typename P::vec>& out, double t, const state<P>& y) {
  using vec = typename P::vec;
  constexpr int d = vec::RowsAtCompileTime;
  vec x, v;
  for (int i = 0; i < d; ++i) x[i] = y[i], v[i] = y[d + i];
  out.record(t, x, v);
}

template <problem P>
void finish(drive_result<typename P::vec>& out, const state<P>& y, double t, long calls) {
  using vec = typename P::vec;
  constexpr int d = vec::RowsAtCompileTime;
  out.t_final = t;
  out.work.force_evals = calls;
  vec x, v;
  for (int i = 0; i < d; ++i) x[i] = y[i], v[i] = y[d + i];
  out.final_state = {x, v};
  out.non_finite = out.non_finite || !all_finite(out.final_state.x, out.final_state.v);
}
}  // namespace odeint_detail

// The controlled steppers, each made as a user would.
struct odeint_dopri5_tag {
  static constexpr const char* name = "odeint_dopri5_adaptive";
  static constexpr const char* description = "Boost.Odeint controlled runge_kutta_dopri5 (Dormand-Prince 5(4))";
  static constexpr double evals_per_step = 6.0;
  template <class S>
  static double order() {
    return boost::numeric::odeint::runge_kutta_dopri5<S>::order_value;
  }
  template <class S>
  static auto make(double tol) {
    return boost::numeric::odeint::make_controlled(tol, tol, boost::numeric::odeint::runge_kutta_dopri5<S>());
  }
};
struct odeint_rkf78_tag {
  static constexpr const char* name = "odeint_rkf78_adaptive";
  static constexpr const char* description =
      "Boost.Odeint controlled runge_kutta_fehlberg78 (Fehlberg 7(8), 13 stages)";
  static constexpr double evals_per_step = 13.0;
  template <class S>
  static double order() {
    return boost::numeric::odeint::runge_kutta_fehlberg78<S>::order_value;
  }
  template <class S>
  static auto make(double tol) {
    return boost::numeric::odeint::make_controlled(tol, tol, boost::numeric::odeint::runge_kutta_fehlberg78<S>());
  }
};
// Bulirsch-Stoer (Odeint's bulirsch_stoer: modified midpoint with Richardson extrapolation,
// step size and order both adapted, up to 8 extrapolation levels): no fixed order.
struct odeint_bulirsch_stoer_tag {
  static constexpr const char* name = "odeint_bulirsch_stoer";
  static constexpr const char* description = "Boost.Odeint bulirsch_stoer (extrapolation; order and step adapted)";
  static constexpr double evals_per_step = 20.0;
  template <class S>
  static double order() {
    return std::numeric_limits<double>::quiet_NaN();
  }
  template <class S>
  static auto make(double tol) {
    return boost::numeric::odeint::bulirsch_stoer<S>(tol, tol);
  }
};

// GCC 12 warns that the copy of a default-constructed Odeint stepper inside
// controlled_runge_kutta's constructor reads its (uninitialised) stage arrays; the copy
// happens before any step writes them and nothing reads them before that.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
template <class Tag>
struct odeint_adaptive {
  static method_info info() {
    return {Tag::name,
            Tag::description,
            method_origin::peer,
            method_kind::adaptive,
            Tag::template order<std::array<double, 2>>(),
            {.error_estimate = true},
            "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = odeint_detail::fixed_size<P>;

  template <problem P>
  static auto prepare(const P& p, double tol, double horizon, std::span<const double> times, const run_limits& limits) {
    const long max_steps = limits.adaptive_steps(p.dim(), Tag::evals_per_step);
    return [p, tol, horizon, max_steps, t = std::vector<double>(times.begin(), times.end())] {
      return run(p, tol, horizon, t, max_steps);
    };
  }

  template <problem P>
  STEPBENCH_FLATTEN static drive_result<typename P::vec> run(const P& p, double tol, double horizon,
                                                             std::span<const double> times, long max_steps) {
    namespace odeint = boost::numeric::odeint;
    using state = odeint_detail::state<P>;
    long calls = 0;
    const first_order_form<P> rhs(p);
    auto system = [&](const state& y, state& dydt, double t) {
      ++calls;
      rhs(t, y.data(), dydt.data());
    };
    auto stepper = Tag::template make<state>(tol);
    state y = odeint_detail::initial_state(p);
    drive_result<typename P::vec> out;
    out.start(p.dim(), times.size());
    double t = 0.0, dt = 1e-6 * times.front();
    for (double tout : times) {
      while (t < tout) {
        double h = std::min(dt, tout - t);
        const bool lands = h == tout - t;
        if (!(h > 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(t), horizon))) {
          out.failure = "step size underflow at t = " + std::to_string(t);
          odeint_detail::finish<P>(out, y, t, calls);
          return out;
        }
        double t_step = t;
        if (stepper.try_step(system, y, t_step, h) == odeint::success) {
          ++out.steps;
          t = lands ? tout : t_step;
          dt = std::max(dt, h);  // h now holds the proposed next step
          if (out.steps >= max_steps && t < horizon) {
            out.over_budget = true;
            out.failure = "over the step budget of " + std::to_string(max_steps) + " steps at t = " + std::to_string(t);
            odeint_detail::finish<P>(out, y, t, calls);
            return out;
          }
        } else {
          ++out.rejected_steps;
          dt = h;
          if (!std::isfinite(dt)) {
            out.non_finite = true;
            odeint_detail::finish<P>(out, y, t, calls);
            return out;
          }
        }
      }
      if (!std::all_of(y.begin(), y.end(), [](double v) { return std::isfinite(v); })) {
        out.non_finite = true;
        break;
      }
      odeint_detail::record<P>(out, t, y);
    }
    odeint_detail::finish<P>(out, y, t, calls);
    return out;
  }
};

#pragma GCC diagnostic pop

// runge_kutta_fehlberg78 at our dt: the library's eighth-order step in our fixed-step loop
// (13 evaluations a step; do_step without the error estimate).
struct odeint_rkf78 {
  static method_info info() {
    return {"odeint_rkf78",
            "Boost.Odeint runge_kutta_fehlberg78 at fixed dt, on std::array",
            method_origin::peer,
            method_kind::fixed_step,
            static_cast<double>(boost::numeric::odeint::runge_kutta_fehlberg78<std::array<double, 2>>::order_value),
            {},
            "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = odeint_detail::fixed_size<P>;

  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return run(p, dt, horizon, plan); };
  }

  template <problem P>
  STEPBENCH_FLATTEN static drive_result<typename P::vec> run(const P& p, double dt, double horizon,
                                                             std::span<const record_point> plan) {
    using state = odeint_detail::state<P>;
    long calls = 0;
    const first_order_form<P> rhs(p);
    auto system = [&](const state& y, state& dydt, double t) {
      ++calls;
      rhs(t, y.data(), dydt.data());
    };
    boost::numeric::odeint::runge_kutta_fehlberg78<state> stepper;
    state y = odeint_detail::initial_state(p);
    drive_result<typename P::vec> out;
    out.start(p.dim(), plan.size());
    const loop_end end = fixed_step_loop(
        dt, horizon, plan, [&](double t, double h) { stepper.do_step(system, y, t, h); }, [](double) {},
        [&](double t) {
          if (!std::all_of(y.begin(), y.end(), [](double v) { return std::isfinite(v); }))
            return out.non_finite = true, false;
          odeint_detail::record<P>(out, t, y);
          return true;
        });
    out.steps = end.steps;
    odeint_detail::finish<P>(out, y, end.t, calls);
    return out;
  }
};
#endif

}  // namespace stepbench::peers

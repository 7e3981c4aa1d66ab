#pragma once
// Boost.Odeint's high-order solvers, what a C++ user picks for tight accuracy, on
// std::array (problems with a fixed-size state; STEPBENCH_HAVE_ODEINT):
//  - adaptive, over the tolerance ladder (eps_abs = eps_rel = tol, Odeint's default error
//    checker): controlled runge_kutta_dopri5 (`odeint_dopri5_adaptive`), controlled
//    runge_kutta_fehlberg78 (`odeint_rkf78_adaptive`) and bulirsch_stoer
//    (`odeint_bulirsch_stoer`);
// (runge_kutta_fehlberg78 at our dt, `odeint_rkf78`, is in peers/odeint.hpp with the
// other fixed-step Odeint peers.)
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
#include "peers/odeint.hpp"

#if STEPBENCH_HAVE_ODEINT
#include <boost/numeric/odeint/stepper/bulirsch_stoer.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#endif

namespace stepbench::peers {

#if STEPBENCH_HAVE_ODEINT

// The controlled steppers, each made as a user would: make_controlled(eps_abs, eps_rel,
// the error stepper).
template <template <class...> class ErrorStepper>
struct odeint_controlled {
  template <class S>
  static double order() {
    return ErrorStepper<S>::order_value;
  }
  template <class S>
  static auto make(double tol) {
    return boost::numeric::odeint::make_controlled(tol, tol, ErrorStepper<S>());
  }
};
struct odeint_dopri5_tag : odeint_controlled<boost::numeric::odeint::runge_kutta_dopri5> {
  static constexpr const char* name = "odeint_dopri5_adaptive";
  static constexpr const char* description = "Boost.Odeint controlled runge_kutta_dopri5 (Dormand-Prince 5(4))";
  static constexpr double evals_per_step = 6.0;
};
struct odeint_rkf78_tag : odeint_controlled<boost::numeric::odeint::runge_kutta_fehlberg78> {
  static constexpr const char* name = "odeint_rkf78_adaptive";
  static constexpr const char* description =
      "Boost.Odeint controlled runge_kutta_fehlberg78 (Fehlberg 7(8), 13 stages)";
  static constexpr double evals_per_step = 13.0;
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
    return {.name = Tag::name,
            .description = Tag::description,
            .origin = method_origin::peer,
            .kind = method_kind::adaptive,
            .declared_order = Tag::template order<std::array<double, 2>>(),
            .traits = {.error_estimate = true},
            .library = "Boost.Odeint"};
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
          out.stop_reason = "step size underflow at t = " + std::to_string(t);
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
            out.stop_reason =
                "over the step budget of " + std::to_string(max_steps) + " steps at t = " + std::to_string(t);
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
      if (!odeint_detail::record_if_finite<P>(out, t, y)) break;
    }
    odeint_detail::finish<P>(out, y, t, calls);
    return out;
  }
};

#pragma GCC diagnostic pop

#endif

}  // namespace stepbench::peers

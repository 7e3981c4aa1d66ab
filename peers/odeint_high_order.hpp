#pragma once
// Boost.Odeint's high-order solvers, what a C++ user picks for tight accuracy, on
// std::array (problems with a fixed-size state; STEPBENCH_HAVE_ODEINT):
//  - adaptive, over the tolerance ladder (eps_abs = eps_rel = tol, Odeint's default error
//    checker): controlled runge_kutta_dopri5 (`odeint_dopri5_adaptive`), controlled
//    runge_kutta_fehlberg78 (`odeint_rkf78_adaptive`) and bulirsch_stoer
//    (`odeint_bulirsch_stoer`);
// (runge_kutta_fehlberg78 at our dt, `odeint_rkf78`, is in peers/odeint.hpp with the
// other fixed-step Odeint peers.)
// Their loop is integrate_times' (adaptive_peer, core/step_adapter.hpp).
#include <array>
#include <limits>

#include "core/first_order.hpp"
#include "core/method.hpp"
#include "core/step_adapter.hpp"
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
// The descriptor and the step adapter (registered as adaptive_peer<odeint_adaptive<Tag>>,
// whose loop is integrate_times', core/step_adapter.hpp).
template <class Tag>
struct odeint_adaptive {
  static constexpr double evals_per_step = Tag::evals_per_step;
  static method_info describe() {
    return {.name = Tag::name,
            .description = Tag::description,
            .origin = method_origin::peer,
            .declared_order = Tag::template order<std::array<double, 2>>(),
            .traits = {.error_estimate = true},
            .library = "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = odeint_detail::fixed_size<P>;

  template <problem P>
  struct adapter : odeint_detail::first_order_state<P> {
    decltype(Tag::template make<odeint_detail::state<P>>(1.0)) stepper;
    adapter(const P& p, double tol)
        : odeint_detail::first_order_state<P>(p), stepper(Tag::template make<odeint_detail::state<P>>(tol)) {}
    bool try_step(double& t, double& h) {
      return stepper.try_step(this->system(), this->y, t, h) == boost::numeric::odeint::success;
    }
  };
};

#pragma GCC diagnostic pop

#endif

}  // namespace stepbench::peers

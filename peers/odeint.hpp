#pragma once
// Boost.Odeint's fixed-step steppers at our dt, on std::array, where Boost's headers are
// present (STEPBENCH_HAVE_ODEINT): runge_kutta4 (`odeint_rk4`), runge_kutta_fehlberg78
// (`odeint_rkf78`: the library's eighth-order step without its error estimate, 13
// evaluations a step, for the step-cost comparison with rk8) and velocity_verlet. Odeint
// needs the state size at compile time here, so these peers apply to problems with a
// fixed-size state. The state helpers below serve the adaptive Odeint peers too
// (peers/odeint_high_order.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <utility>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"

#if STEPBENCH_HAVE_ODEINT
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#include <boost/numeric/odeint/stepper/velocity_verlet.hpp>
#endif

namespace stepbench::peers {

#if STEPBENCH_HAVE_ODEINT
namespace odeint_detail {

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

// The state at a record point, copied into the result; false (and the run marked
// non-finite) when a coordinate is NaN or infinite, which ends the run there. (Copied
// coordinate by coordinate: GCC 12 misreads Eigen's packet copy from a Map of the second
// half of the std::array as reading past it, -Wstringop-overread.)
template <problem P>
bool record_if_finite(drive_result<typename P::vec>& out, double t, const state<P>& y) {
  if (!std::all_of(y.begin(), y.end(), [](double c) { return std::isfinite(c); })) return out.non_finite = true, false;
  using vec = typename P::vec;
  constexpr int d = vec::RowsAtCompileTime;
  vec x, v;
  for (int i = 0; i < d; ++i) x[i] = y[i], v[i] = y[d + i];
  out.record(t, x, v);
  return true;
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

// A first-order Odeint stepper at our dt: [x; v] as Odeint's state, the problem through
// first_order_form, our fixed-step loop around do_step.
struct odeint_rk4_step {
  static constexpr const char* name = "odeint_rk4";
  static constexpr const char* description = "Boost.Odeint runge_kutta4 on std::array";
  template <class S>
  using stepper = boost::numeric::odeint::runge_kutta4<S>;
};
struct odeint_rkf78_step {
  static constexpr const char* name = "odeint_rkf78";
  static constexpr const char* description = "Boost.Odeint runge_kutta_fehlberg78 at fixed dt, on std::array";
  template <class S>
  using stepper = boost::numeric::odeint::runge_kutta_fehlberg78<S>;
};

template <class Tag>
struct odeint_fixed {
  static method_info info() {
    return {.name = Tag::name,
            .description = Tag::description,
            .origin = method_origin::peer,
            .kind = method_kind::fixed_step,
            .declared_order = static_cast<double>(Tag::template stepper<std::array<double, 2>>::order_value),
            .library = "Boost.Odeint"};
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
    typename Tag::template stepper<state> stepper;
    state y = odeint_detail::initial_state(p);
    drive_result<typename P::vec> out;
    out.start(p.dim(), plan.size());
    const loop_end end = fixed_step_loop(
        dt, horizon, plan, [&](double t, double h) { stepper.do_step(system, y, t, h); }, [](double) {},
        [&](double t) { return odeint_detail::record_if_finite<P>(out, t, y); });
    out.steps = end.steps;
    odeint_detail::finish<P>(out, y, end.t, calls);
    return out;
  }
};

using odeint_rk4 = odeint_fixed<odeint_rk4_step>;
using odeint_rkf78 = odeint_fixed<odeint_rkf78_step>;

// Odeint's velocity_verlet is a second-order-system stepper: the system returns the
// acceleration a(x, v, t). It declares order() == 1 (Boost 1.74) although the scheme is
// second order; the study fits what it achieves and reports both.
struct odeint_velocity_verlet {
  static method_info info() {
    return {.name = "odeint_velocity_verlet",
            .description = "Boost.Odeint velocity_verlet on std::array (declares order 1)",
            .origin = method_origin::peer,
            .kind = method_kind::fixed_step,
            .declared_order =
                static_cast<double>(boost::numeric::odeint::velocity_verlet<std::array<double, 1>>::order_value),
            .library = "Boost.Odeint"};
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
    using vec = typename P::vec;
    constexpr int d = vec::RowsAtCompileTime;
    using coord = std::array<double, d>;
    long calls = 0;
    const double inv_mass = 1.0 / p.mass();
    vec xe, ve, fe;
    auto accel = [&](const coord& x, const coord& v, coord& a, double t) {
      ++calls;
      xe = Eigen::Map<const vec>(x.data());
      ve = Eigen::Map<const vec>(v.data());
      p.force(t, xe, ve, fe);
      Eigen::Map<vec>(a.data()) = fe * inv_mass;
    };
    boost::numeric::odeint::velocity_verlet<coord> stepper;
    coord x, v;
    const auto s0 = p.initial();
    for (int i = 0; i < d; ++i) x[i] = s0.x[i], v[i] = s0.v[i];
    drive_result<vec> out;
    out.start(d, plan.size());
    const loop_end end = fixed_step_loop(
        dt, horizon, plan,
        [&](double t, double h) { stepper.do_step(accel, std::make_pair(std::ref(x), std::ref(v)), t, h); },
        [](double) {},
        [&](double t) {
          const auto xe = Eigen::Map<const vec>(x.data()), ve = Eigen::Map<const vec>(v.data());
          if (!all_finite(vec(xe), vec(ve))) return out.non_finite = true, false;
          out.record(t, xe, ve);
          return true;
        });
    out.steps = end.steps;
    out.t_final = end.t;
    out.work.force_evals = calls;
    out.final_state = {Eigen::Map<const vec>(x.data()), Eigen::Map<const vec>(v.data())};
    out.non_finite = out.non_finite || !all_finite(out.final_state.x, out.final_state.v);
    return out;
  }
};
#endif

}  // namespace stepbench::peers

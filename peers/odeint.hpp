#pragma once
// Boost.Odeint's runge_kutta4 and velocity_verlet on std::array, at our dt, where
// Boost's headers are present (STEPBENCH_HAVE_ODEINT). Odeint needs the state size at
// compile time here, so these peers apply to problems with a fixed-size state.
#include <algorithm>
#include <array>
#include <span>
#include <utility>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"

#if STEPBENCH_HAVE_ODEINT
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/velocity_verlet.hpp>
#endif

namespace stepbench::peers {

#if STEPBENCH_HAVE_ODEINT
template <problem P>
inline constexpr bool fixed_size_state = P::vec::RowsAtCompileTime != Eigen::Dynamic;

// The recording shared by both: [x; v] held as Odeint's state, copied into the result.
template <class Vec, class X, class V>
inline bool odeint_record(drive_result<Vec>& out, double t, const X& x, const V& v) {
  const auto xe = Eigen::Map<const Vec>(x.data()), ve = Eigen::Map<const Vec>(v.data());
  if (!all_finite(Vec(xe), Vec(ve))) return out.non_finite = true, false;
  out.record(t, xe, ve);
  return true;
}

struct odeint_rk4 {
  static method_info info() {
    return {"odeint_rk4",
            "Boost.Odeint runge_kutta4 on std::array",
            method_origin::peer,
            method_kind::fixed_step,
            static_cast<double>(boost::numeric::odeint::runge_kutta4<std::array<double, 2>>::order_value),
            {},
            "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = fixed_size_state<P>;

  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return run(p, dt, horizon, plan); };
  }

  template <problem P>
  STEPBENCH_FLATTEN static drive_result<typename P::vec> run(const P& p, double dt, double horizon,
                                                             std::span<const record_point> plan) {
    using vec = typename P::vec;
    constexpr int d = vec::RowsAtCompileTime;
    using state = std::array<double, 2 * d>;
    long calls = 0;
    const first_order_form<P> rhs(p);
    auto system = [&](const state& y, state& dydt, double t) {
      ++calls;
      rhs(t, y.data(), dydt.data());
    };
    boost::numeric::odeint::runge_kutta4<state> stepper;
    state y;
    const auto s0 = p.initial();
    for (int i = 0; i < d; ++i) y[i] = s0.x[i], y[d + i] = s0.v[i];
    drive_result<vec> out;
    out.start(d, plan.size());
    const loop_end end = fixed_step_loop(
        dt, horizon, plan, [&](double t, double h) { stepper.do_step(system, y, t, h); }, [](double) {},
        [&](double t) {
          return odeint_record(out, t, std::span<const double>(y.data(), d), std::span<const double>(y.data() + d, d));
        });
    out.steps = end.steps;
    out.t_final = end.t;
    out.work.force_evals = calls;
    out.final_state = {Eigen::Map<const vec>(y.data()), Eigen::Map<const vec>(y.data() + d)};
    out.non_finite = out.non_finite || !all_finite(out.final_state.x, out.final_state.v);
    return out;
  }
};

// Odeint's velocity_verlet is a second-order-system stepper: the system returns the
// acceleration a(x, v, t). It declares order() == 1 (Boost 1.74) although the scheme is
// second order; the study fits what it achieves and reports both.
struct odeint_velocity_verlet {
  static method_info info() {
    return {"odeint_velocity_verlet",
            "Boost.Odeint velocity_verlet on std::array (declares order 1)",
            method_origin::peer,
            method_kind::fixed_step,
            static_cast<double>(boost::numeric::odeint::velocity_verlet<std::array<double, 1>>::order_value),
            {},
            "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = fixed_size_state<P>;

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
        [](double) {}, [&](double t) { return odeint_record(out, t, x, v); });
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

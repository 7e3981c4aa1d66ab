#pragma once
// Boost.Odeint's fixed-step steppers at our dt, on std::array, where Boost's headers are
// present (STEPBENCH_HAVE_ODEINT): runge_kutta4 (`odeint_rk4`), runge_kutta_fehlberg78
// (`odeint_rkf78`: the library's eighth-order step without its error estimate, 13
// evaluations a step, for the step-cost comparison with rk8) and velocity_verlet. Odeint
// needs the state size at compile time here, so these peers apply to problems with a
// fixed-size state. The state helpers below serve the adaptive Odeint peers too
// (peers/odeint_high_order.hpp).
#include <array>
#include <utility>

#include "core/first_order.hpp"
#include "core/method.hpp"
#include "core/step_adapter.hpp"

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

// What the first-order Odeint adapters hold: the state [x; v] in Odeint's std::array, the
// problem through first_order_form, and the right-hand side's calls counted.
template <problem P>
struct first_order_state {
  static constexpr int d = P::vec::RowsAtCompileTime;
  first_order_form<P> rhs;
  long calls = 0;
  state<P> y;

  explicit first_order_state(const P& p) : rhs(p) {
    const auto s0 = p.initial();
    for (int i = 0; i < d; ++i) y[i] = s0.x[i], y[d + i] = s0.v[i];
  }
  first_order_state(const first_order_state&) = delete;

  // The system as Odeint calls it.
  auto system() {
    return [this](const state<P>& yy, state<P>& dydt, double tt) {
      ++calls;
      rhs(tt, yy.data(), dydt.data());
    };
  }
  // The state as two vectors (copied coordinate by coordinate: GCC 12 misreads Eigen's
  // packet copy from a Map of the second half of the std::array as reading past it,
  // -Wstringop-overread).
  template <class Vec>
  void state_into(Vec& x, Vec& v) const {
    for (int i = 0; i < d; ++i) x[i] = y[i], v[i] = y[d + i];
  }
  long force_evals() const { return calls; }
};
}  // namespace odeint_detail

// A first-order Odeint stepper at our dt: [x; v] as Odeint's state, the problem through
// first_order_form, our fixed-step loop around do_step.
struct odeint_rk4_step {
  static constexpr const char* name = "odeint_rk4";
  static constexpr const char* description = "Boost.Odeint runge_kutta4 on std::array";
  static constexpr double evals_per_step = 4.0;
  template <class S>
  using stepper = boost::numeric::odeint::runge_kutta4<S>;
};
struct odeint_rkf78_step {
  static constexpr const char* name = "odeint_rkf78";
  static constexpr const char* description = "Boost.Odeint runge_kutta_fehlberg78 at fixed dt, on std::array";
  static constexpr double evals_per_step = 13.0;
  template <class S>
  using stepper = boost::numeric::odeint::runge_kutta_fehlberg78<S>;
};

// The descriptor and the step adapter (registered as fixed_step_peer<odeint_fixed<Tag>>,
// core/step_adapter.hpp).
template <class Tag>
struct odeint_fixed {
  static method_info describe() {
    return {.name = Tag::name,
            .description = Tag::description,
            .origin = method_origin::peer,
            .declared_order = static_cast<double>(Tag::template stepper<std::array<double, 2>>::order_value),
            .evals_per_step = Tag::evals_per_step,
            .library = "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = odeint_detail::fixed_size<P>;

  template <problem P>
  struct adapter : odeint_detail::first_order_state<P> {
    typename Tag::template stepper<odeint_detail::state<P>> stepper;
    using odeint_detail::first_order_state<P>::first_order_state;
    void step(double t, double h) { stepper.do_step(this->system(), this->y, t, h); }
  };
};

using odeint_rk4 = fixed_step_peer<odeint_fixed<odeint_rk4_step>>;
using odeint_rkf78 = fixed_step_peer<odeint_fixed<odeint_rkf78_step>>;

// Odeint's velocity_verlet is a second-order-system stepper: the system returns the
// acceleration a(x, v, t). It declares order() == 1 (Boost 1.74) although the scheme is
// second order; the study fits what it achieves and reports both.
struct odeint_velocity_verlet {
  static method_info describe() {
    return {.name = "odeint_velocity_verlet",
            .description = "Boost.Odeint velocity_verlet on std::array (declares order 1)",
            .origin = method_origin::peer,
            .declared_order =
                static_cast<double>(boost::numeric::odeint::velocity_verlet<std::array<double, 1>>::order_value),
            .library = "Boost.Odeint"};
  }
  template <problem P>
  static constexpr bool applies = odeint_detail::fixed_size<P>;

  template <problem P>
  struct adapter {
    using vec = typename P::vec;
    static constexpr int d = vec::RowsAtCompileTime;
    using coord = std::array<double, d>;
    const P& p;
    const double inv_mass;
    long calls = 0;
    vec xe, ve, fe;
    boost::numeric::odeint::velocity_verlet<coord> stepper;
    coord x, v;

    explicit adapter(const P& problem) : p(problem), inv_mass(1.0 / problem.mass()) {
      const auto s0 = p.initial();
      for (int i = 0; i < d; ++i) x[i] = s0.x[i], v[i] = s0.v[i];
    }
    adapter(const adapter&) = delete;

    void step(double t, double h) {
      // Odeint's second-order-system form: the system returns the acceleration a(x, v, t).
      auto accel = [this](const coord& xc, const coord& vc, coord& a, double tt) {
        ++calls;
        xe = Eigen::Map<const vec>(xc.data());
        ve = Eigen::Map<const vec>(vc.data());
        p.force(tt, xe, ve, fe);
        Eigen::Map<vec>(a.data()) = fe * inv_mass;
      };
      stepper.do_step(accel, std::make_pair(std::ref(x), std::ref(v)), t, h);
    }
    template <class Vec>
    void state_into(Vec& xo, Vec& vo) const {
      for (int i = 0; i < d; ++i) xo[i] = x[i], vo[i] = v[i];
    }
    long force_evals() const { return calls; }
  };
};
#endif

}  // namespace stepbench::peers

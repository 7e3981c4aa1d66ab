#pragma once
// Methods that are a tableau and nothing else (not methods themselves: templates that a
// method's header names with its coefficients; integrators/verner.hpp):
//  - fixed_tableau<T, D>: the higher-order solution b of T at a fixed dt;
//  - embedded_pair<T, D>: the pair (b, b_hat) of T made adaptive by the one step-size
//    controller (integrators/step_control.hpp), as Boost.Odeint's controlled_runge_kutta
//    makes any error stepper adaptive: the error estimate sum (b_i - b_hat_i) k_i in the
//    scaled RMS norm, the controller D::control (the elementary one or Gustafsson's PI
//    term, chosen by the method), Hairer's starting step.
// D (the method's descriptor) gives name and description, for a pair its controller, and
// may restrict the problems it runs on (`applies`, core/method.hpp's method_applies).
// The stages are integrators/unrolled_rk.hpp's (the Nystrom form for a position-only
// force). No dense output: the drive loop shortens the steps that would pass a sample
// time (core/drive.hpp).
#include <array>
#include <cstddef>
#include <string_view>

#include "core/concepts.hpp"
#include "core/method.hpp"
#include "integrators/step_control.hpp"
#include "integrators/tableau.hpp"
#include "integrators/unrolled_rk.hpp"

namespace stepbench {

namespace tableau_detail {

// The stages up to the last with a nonzero weight in w: the ones a step evaluates.
template <std::size_t S>
constexpr int stages_used(const std::array<double, S>& w) {
  int n = 0;
  for (std::size_t i = 0; i < S; ++i)
    if (w[i] != 0.0) n = static_cast<int>(i) + 1;
  return n;
}

// First same as last: the last stage is evaluated at the new state (its row of A is b,
// c = 1), so an accepted step's last force is the next step's first.
template <int S>
constexpr bool fsal(const explicit_tableau<S>& t) {
  return t.c[S - 1] == 1.0 && t.a[S - 1] == t.b;
}

template <int S>
constexpr std::array<double, S> error_weights(const explicit_tableau<S>& t) {
  std::array<double, S> e{};
  for (int i = 0; i < S; ++i) e[i] = t.b[i] - t.b_hat[i];
  return e;
}

}  // namespace tableau_detail

template <const auto& T, class D>
struct fixed_tableau {
  static constexpr std::string_view name = D::name;
  static constexpr std::string_view description = D::description;
  static constexpr int order = T.order;
  static constexpr capabilities traits{};
  template <class P>
  static constexpr bool applies = method_applies<D, P>();
  // The stages b weighs; f(t + dt, y_1) is the next step's first stage.
  static constexpr int force_evals_per_step = tableau_detail::stages_used(T.b);

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    unrolled_rk<T, Sys> k;
    explicit stepper(const fixed_tableau&) {}
    void resize(const Sys&, const Vec& like) { k.resize(like); }

    void step(const Sys& sys, double t, step_state<Vec>& s, double dt) {
      const double h_im = dt * inverse_mass(sys);
      k.F[0] = current_force(sys, t, s);
      k.template compute<1, force_evals_per_step>(sys, t, s.x, s.v, dt, h_im);
      k.template combine<T.b>(s.x, s.v, s.x, s.v, dt, h_im);
      s.f_current = false;
    }
  };
};

template <const auto& T, class D>
struct embedded_pair {
  static_assert(T.embedded_order > 0, "an embedded pair needs b_hat");
  static constexpr std::string_view name = D::name;
  static constexpr std::string_view description = D::description;
  static constexpr int order = T.order;
  template <class P>
  static constexpr bool applies = method_applies<D, P>();
  static constexpr int S = std::remove_cvref_t<decltype(T)>::stages;
  static constexpr bool fsal = tableau_detail::fsal(T);
  static constexpr capabilities traits{.reuses_last_force = fsal, .error_estimate = true};
  // Every stage, the first being f at the step's start: the last accepted step's last
  // stage with FSAL, else one evaluation at the new state.
  static constexpr int force_evals_per_step = fsal ? S - 1 : S;
  static constexpr std::array<double, S> error_weights = tableau_detail::error_weights(T);
  double tol = 1e-6;
  explicit embedded_pair(double tolerance) : tol(tolerance) {}

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    double tol;
    step_controller control = D::control;
    unrolled_rk<T, Sys> k;
    Vec x1, v1, ex, ev;  // the candidate state and its error estimate
    explicit stepper(const embedded_pair& m) : tol(m.tol) {}
    void resize(const Sys&, const Vec& like) {
      k.resize(like);
      size_like(like, x1, v1, ex, ev);
    }

    double initial_dt(const Sys& sys, double t, step_state<Vec>& s, double horizon) {
      return starting_step(sys, t, s, order, tol, horizon, x1, v1, ex);
    }

    step_attempt try_step(const Sys& sys, double t, step_state<Vec>& s, double h) {
      const double h_im = h * inverse_mass(sys);
      k.F[0] = current_force(sys, t, s);
      k.template compute<1, S>(sys, t, s.x, s.v, h, h_im);
      k.template combine<T.b>(x1, v1, s.x, s.v, h, h_im);
      k.template difference<error_weights>(ex, ev, s.v, h, h_im);
      const double err = scaled_rms(ex, ev, s.x, s.v, x1, v1, tol);
      return control.attempt(h, err, [&] {
        s.x = x1;
        s.v = v1;
        if constexpr (fsal) s.f = k.F[S - 1];
        s.f_current = fsal;
      });
    }
  };
};

}  // namespace stepbench

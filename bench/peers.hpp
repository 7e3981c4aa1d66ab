#pragma once
// The peers: what a user might run instead of our integrators, driven over the same
// horizon with the same dt (fixed-step) and recorded at the same sample steps, so
// their errors and times sit beside ours. Each is templated on the problem, like our
// drive loop, so every force model inlines into the peer's callback as it would in a
// user's code.
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <array>
#include <cmath>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/concepts.hpp"
#include "core/drive.hpp"
#include "problems/all.hpp"

#if STEPBENCH_HAVE_ODEINT
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/velocity_verlet.hpp>
#endif

namespace stepbench::peers {

// A peer's run in plain vectors: [x; v] after each recorded step (flat, `width` values
// a sample, one allocation reserved up front as in our own loop, so recording costs the
// peers no more than it costs us) and at the end.
struct peer_run {
  long steps = 0;
  long force_evals = 0;
  bool non_finite = false;
  int width = 0;
  std::vector<double> samples;
  std::vector<double> final_y;
  size_t sample_count() const { return width ? samples.size() / width : 0; }
  std::span<const double> sample(size_t j) const { return {samples.data() + j * width, static_cast<size_t>(width)}; }
  void start(int n, size_t count) {
    width = n;
    samples.reserve(count * n);
  }
  template <class It>
  void record(It first, It last) {
    samples.insert(samples.end(), first, last);
  }
};


inline bool finite(std::span<const double> y) {
  for (double v : y)
    if (!std::isfinite(v)) return false;
  return true;
}

// The fixed-step loop every stepping peer shares with ours: steps of exactly dt but a
// shortened last one, t = i dt, and the state recorded after each step in `record`.
// `step(t, h)` advances the peer's state; `state()` returns it as [x; v] (an iterable of
// 2 dim values). A non-finite recorded state stops the run.
template <class Step, class State>
void drive_fixed(peer_run& out, double dt, double horizon, std::span<const long> record, Step&& step, State&& state) {
  const long steps = steps_for(horizon, dt);
  auto next = record.begin();
  double t = 0.0;
  long i = 0;
  while (i < steps) {
    step(t, i + 1 == steps ? horizon - t : dt);
    t = time_after_step(++i, steps, dt, horizon);
    if (next != record.end() && *next == i) {
      ++next;
      const auto y = state();
      if (!finite(y)) {
        out.non_finite = true;
        break;
      }
      out.record(y.begin(), y.end());
    }
  }
  out.steps = i;
  const auto y = state();
  out.final_y.assign(y.begin(), y.end());
  out.non_finite = out.non_finite || !finite(y);
}

// ---- GSL fixed-step: gsl_odeiv2_step_apply at our dt -------------------------------
// As the GSL manual recommends for a fixed-step loop: dydt_out of one step is passed as
// dydt_in of the next, so no stage is computed twice. GSL's rk4 still estimates its
// error by step doubling (a full step and two half steps), and rkf45 by its embedded
// pair: work a user pays for whether or not they use the estimate.

template <problem P>
struct gsl_context {
  const P* problem;
  double inv_mass;
  long calls = 0;
};

template <problem P>
int gsl_rhs(double t, const double y[], double dydt[], void* params) {
  auto& c = *static_cast<gsl_context<P>*>(params);
  ++c.calls;
  first_order_rhs(*c.problem, c.inv_mass, t, y, dydt);
  return GSL_SUCCESS;
}

struct gsl_step_deleter {
  void operator()(gsl_odeiv2_step* s) const { gsl_odeiv2_step_free(s); }
};

template <problem P>
peer_run gsl_fixed(const P& p, const gsl_odeiv2_step_type* type, double dt, double horizon,
                   std::span<const long> record) {
  constexpr int n = 2 * P::dim;
  gsl_context<P> ctx{&p, 1.0 / p.mass()};
  gsl_odeiv2_system sys{&gsl_rhs<P>, nullptr, n, &ctx};
  std::unique_ptr<gsl_odeiv2_step, gsl_step_deleter> step(gsl_odeiv2_step_alloc(type, n));
  if (!step) throw std::runtime_error("gsl_odeiv2_step_alloc failed");
  std::array<double, n> y, yerr, dydt_in, dydt_out;
  const auto s0 = p.initial();
  for (int i = 0; i < P::dim; ++i) y[i] = s0.x[i], y[P::dim + i] = s0.v[i];
  gsl_rhs<P>(0.0, y.data(), dydt_in.data(), &ctx);

  peer_run out;
  out.start(n, record.size());
  drive_fixed(
      out, dt, horizon, record,
      [&](double t, double h) {
        const int status = gsl_odeiv2_step_apply(step.get(), t, h, y.data(), yerr.data(), dydt_in.data(),
                                                 dydt_out.data(), &sys);
        if (status != GSL_SUCCESS) throw std::runtime_error(std::string("gsl_odeiv2_step_apply: ") + gsl_strerror(status));
        dydt_in = dydt_out;
      },
      [&] { return y; });
  out.force_evals = ctx.calls;
  return out;
}

// ---- Hand-written RK4 on plain doubles: the speed-of-light baseline ---------------
// The best a programmer can write for one scalar degree of freedom: the acceleration
// spelled out with constants folded, no abstraction, no Eigen, no counting wrapper, the
// same latency ordering as ours. Same recording of samples as our loop, so the
// comparison is of the step alone.

// The acceleration spelled out with the problem's constants folded and copied into
// locals first, as a programmer writing one scalar loop by hand would: a = -(k/m) x -
// (c/m) v, no division, no separate multiplication by 1/m. (Constants read from the
// problem inside the loop would be reloaded every stage: the loop stores samples, which
// the compiler must assume could alias the problem.)
inline auto baseline_acceleration(const damped_spring& p) {
  return [km = p.k_s / p.mass_kg, cm = p.k_d / p.mass_kg](double x, double v) { return -cm * v - km * x; };
}
inline auto baseline_acceleration(const pendulum& p) {
  return [g_over_l = p.gravity / p.length_m](double x, double) { return -g_over_l * std::sin(x); };
}

template <class P>
concept has_baseline = requires(const P& p) { baseline_acceleration(p)(0.0, 0.0); };

template <has_baseline P>
peer_run baseline_rk4(const P& p, double dt, double horizon, std::span<const long> record) {
  const auto accel = baseline_acceleration(p);
  const auto s0 = p.initial();
  double x = s0.x[0], v = s0.v[0];
  const long steps = steps_for(horizon, dt);
  peer_run out;
  out.start(2, record.size());
  auto next = record.begin();
  for (long i = 0; i < steps; ++i) {
    const double h = i + 1 == steps ? horizon - static_cast<double>(i) * dt : dt, h2 = 0.5 * h;
    const double a1 = accel(x, v);
    const double x2 = x + h2 * v, v2 = v + h2 * a1, a2 = accel(x2, v2);
    const double x3 = x + h2 * v2, v3 = v + h2 * a2, a3 = accel(x3, v3);
    const double x4 = x + h * v3, v4 = v + h * a3;
    // Partial sums first, so one multiply-add follows the last acceleration (as in ours).
    const double w = h / 6.0, x_123 = x + w * (v + 2.0 * (v2 + v3)), v_123 = v + w * (a1 + 2.0 * (a2 + a3));
    const double a4 = accel(x4, v4);
    x = x_123 + w * v4;
    v = v_123 + w * a4;
    if (next != record.end() && *next == i + 1) {
      ++next;
      const double y[2] = {x, v};
      out.record(y, y + 2);
    }
  }
  out.steps = steps;
  out.force_evals = 4 * steps;
  out.non_finite = !std::isfinite(x) || !std::isfinite(v);
  out.final_y = {x, v};
  return out;
}

#if STEPBENCH_HAVE_ODEINT
// ---- Boost.Odeint: runge_kutta4 and velocity_verlet on std::array -------------------

template <problem P>
peer_run odeint_rk4(const P& p, double dt, double horizon, std::span<const long> record) {
  using state = std::array<double, 2 * P::dim>;
  long calls = 0;
  const double inv_mass = 1.0 / p.mass();
  auto system = [&](const state& y, state& dydt, double t) {
    ++calls;
    first_order_rhs(p, inv_mass, t, y.data(), dydt.data());
  };
  boost::numeric::odeint::runge_kutta4<state> stepper;
  state y;
  const auto s0 = p.initial();
  for (int i = 0; i < P::dim; ++i) y[i] = s0.x[i], y[P::dim + i] = s0.v[i];
  peer_run out;
  out.start(2 * P::dim, record.size());
  drive_fixed(
      out, dt, horizon, record, [&](double t, double h) { stepper.do_step(system, y, t, h); }, [&] { return y; });
  out.force_evals = calls;
  return out;
}

// Odeint's velocity_verlet is a second-order-system stepper: the system returns the
// acceleration a(x, v, t). It declares order() == 1 (Boost 1.74) although the scheme is
// second order; the study fits what it achieves and reports both.
template <problem P>
peer_run odeint_velocity_verlet(const P& p, double dt, double horizon, std::span<const long> record) {
  using coord = std::array<double, P::dim>;
  long calls = 0;
  const double inv_mass = 1.0 / p.mass();
  auto accel = [&](const coord& x, const coord& v, coord& a, double t) {
    ++calls;
    typename P::vec xe(P::dim), ve(P::dim);
    for (int i = 0; i < P::dim; ++i) xe[i] = x[i], ve[i] = v[i];
    const typename P::vec ae = p.force(t, xe, ve) * inv_mass;
    for (int i = 0; i < P::dim; ++i) a[i] = ae[i];
  };
  boost::numeric::odeint::velocity_verlet<coord> stepper;
  coord x, v;
  const auto s0 = p.initial();
  for (int i = 0; i < P::dim; ++i) x[i] = s0.x[i], v[i] = s0.v[i];
  peer_run out;
  out.start(2 * P::dim, record.size());
  drive_fixed(
      out, dt, horizon, record,
      [&](double t, double h) { stepper.do_step(accel, std::make_pair(std::ref(x), std::ref(v)), t, h); },
      [&] {
        std::array<double, 2 * P::dim> y;
        std::copy(x.begin(), x.end(), y.begin());
        std::copy(v.begin(), v.end(), y.begin() + P::dim);
        return y;
      });
  out.force_evals = calls;
  return out;
}

inline int odeint_declared_order_rk4() { return boost::numeric::odeint::runge_kutta4<std::array<double, 2>>::order_value; }
inline int odeint_declared_order_velocity_verlet() {
  return boost::numeric::odeint::velocity_verlet<std::array<double, 1>>::order_value;
}
#endif

}  // namespace stepbench::peers

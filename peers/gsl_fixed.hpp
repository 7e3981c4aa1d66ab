#pragma once
// GSL's fixed-step steppers at our dt: gsl_odeiv2_step_apply in our own loop, as the
// GSL manual describes a fixed-step loop: dydt_out of one step is passed as dydt_in of
// the next, so no stage is computed twice. GSL's rk4 still estimates its error by step
// doubling (a full step and two half steps), and rkf45 by its embedded pair: work a
// user pays for whether or not they use the estimate.
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/method.hpp"

namespace stepbench::peers {

struct gsl_step_deleter {
  void operator()(gsl_odeiv2_step* s) const { gsl_odeiv2_step_free(s); }
};

template <problem P>
struct gsl_callback {
  first_order_form<P> rhs;
  long calls = 0;
};

template <problem P>
int gsl_fixed_rhs(double t, const double y[], double dydt[], void* params) {
  auto& c = *static_cast<gsl_callback<P>*>(params);
  ++c.calls;
  c.rhs(t, y, dydt);
  return GSL_SUCCESS;
}

// The GSL steppers a user might run at a fixed step: three here, the fourth (rk8pd) in
// peers/gsl_rk8pd_fixed.hpp.
struct gsl_rk4_tag {
  static constexpr const char* name = "gsl_rk4";
  static constexpr const char* description =
      "GSL rk4 at fixed dt (gsl_odeiv2_step_apply; error estimate by step doubling)";
  static const gsl_odeiv2_step_type* type() { return gsl_odeiv2_step_rk4; }
};
struct gsl_rk2_tag {
  static constexpr const char* name = "gsl_rk2";
  static constexpr const char* description = "GSL rk2 (Heun) at fixed dt, with its embedded error estimate";
  static const gsl_odeiv2_step_type* type() { return gsl_odeiv2_step_rk2; }
};
struct gsl_rkf45_tag {
  static constexpr const char* name = "gsl_rkf45";
  static constexpr const char* description = "GSL rkf45 at fixed dt (Fehlberg 4(5), error estimate unused)";
  static const gsl_odeiv2_step_type* type() { return gsl_odeiv2_step_rkf45; }
};

template <class Stepper>
struct gsl_fixed {
  static method_info info() {
    // The order GSL declares for the stepper (gsl_odeiv2_step_order): the study fits what
    // it achieves and reports both (rk2 advances with the third-order member of its pair).
    std::unique_ptr<gsl_odeiv2_step, gsl_step_deleter> probe(gsl_odeiv2_step_alloc(Stepper::type(), 2));
    return {.name = Stepper::name,
            .description = Stepper::description,
            .origin = method_origin::peer,
            .kind = method_kind::fixed_step,
            .declared_order = static_cast<double>(gsl_odeiv2_step_order(probe.get())),
            .library = "GSL"};
  }

  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return run(p, dt, horizon, plan); };
  }

  template <problem P>
  static drive_result<typename P::vec> run(const P& p, double dt, double horizon, std::span<const record_point> plan) {
    using vec = typename P::vec;
    const int d = p.dim(), n = 2 * d;
    gsl_callback<P> ctx{first_order_form<P>(p)};
    gsl_odeiv2_system sys{&gsl_fixed_rhs<P>, nullptr, static_cast<size_t>(n), &ctx};
    std::unique_ptr<gsl_odeiv2_step, gsl_step_deleter> step(gsl_odeiv2_step_alloc(Stepper::type(), n));
    if (!step) throw std::runtime_error("gsl_odeiv2_step_alloc failed");
    Eigen::Matrix<double, vec::RowsAtCompileTime == Eigen::Dynamic ? Eigen::Dynamic : 2 * vec::RowsAtCompileTime, 1> y(
        n),
        yerr(n), dydt_in(n), dydt_out(n);
    const auto s0 = p.initial();
    y << s0.x, s0.v;
    gsl_fixed_rhs<P>(0.0, y.data(), dydt_in.data(), &ctx);

    drive_result<vec> out;
    out.start(d, plan.size());
    const loop_end end = fixed_step_loop(
        dt, horizon, plan,
        [&](double t, double h) {
          const int status =
              gsl_odeiv2_step_apply(step.get(), t, h, y.data(), yerr.data(), dydt_in.data(), dydt_out.data(), &sys);
          if (status != GSL_SUCCESS)
            throw std::runtime_error(std::string("gsl_odeiv2_step_apply: ") + gsl_strerror(status));
          dydt_in = dydt_out;
        },
        [](double) {},
        [&](double t) {
          if (!y.allFinite()) return out.non_finite = true, false;
          out.record(t, y.head(d), y.tail(d));
          return true;
        });
    out.steps = end.steps;
    out.t_final = end.t;
    out.non_finite = out.non_finite || !y.allFinite();
    out.work.force_evals = ctx.calls;
    out.final_state = {y.head(d), y.tail(d)};
    return out;
  }
};

}  // namespace stepbench::peers

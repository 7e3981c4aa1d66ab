#pragma once
// GSL's fixed-step steppers at our dt: gsl_odeiv2_step_apply as a step adapter on our
// fixed-step loop (core/step_adapter.hpp), as the GSL manual describes a fixed-step
// loop: dydt_out of one step is passed as dydt_in of the next, so no stage is computed
// twice. GSL's rk4 still estimates its error by step doubling (a full step and two half
// steps), and rkf45 and rk8pd by their embedded pairs: work a user pays for whether or
// not they use the estimate.
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "core/first_order.hpp"
#include "core/method.hpp"
#include "core/step_adapter.hpp"

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

// The GSL steppers a user might run at a fixed step.
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
// Prince-Dormand 8(7), 13 stages: the library's eighth-order step, for the step-cost
// comparison with rk8.
struct gsl_rk8pd_tag {
  static constexpr const char* name = "gsl_rk8pd";
  static constexpr const char* description = "GSL rk8pd (Prince-Dormand 8(7)) at fixed dt (gsl_odeiv2_step_apply)";
  static const gsl_odeiv2_step_type* type() { return gsl_odeiv2_step_rk8pd; }
};

// The descriptor and the step adapter of one GSL stepper (registered as
// fixed_step_peer<gsl_fixed<Tag>>, core/step_adapter.hpp).
template <class Stepper>
struct gsl_fixed {
  static method_info describe() {
    // The order GSL declares for the stepper (gsl_odeiv2_step_order): the study fits what
    // it achieves and reports both (rk2 advances with the third-order member of its pair).
    std::unique_ptr<gsl_odeiv2_step, gsl_step_deleter> probe(gsl_odeiv2_step_alloc(Stepper::type(), 2));
    return {.name = Stepper::name,
            .description = Stepper::description,
            .origin = method_origin::peer,
            .declared_order = static_cast<double>(gsl_odeiv2_step_order(probe.get())),
            .library = "GSL"};
  }

  template <problem P>
  struct adapter {
    using vec = typename P::vec;
    using state =
        Eigen::Matrix<double, vec::RowsAtCompileTime == Eigen::Dynamic ? Eigen::Dynamic : 2 * vec::RowsAtCompileTime,
                      1>;
    int d;
    gsl_callback<P> ctx;
    gsl_odeiv2_system sys;
    std::unique_ptr<gsl_odeiv2_step, gsl_step_deleter> stepper;
    state y, yerr, dydt_in, dydt_out;

    explicit adapter(const P& p)
        : d(p.dim()),
          ctx{first_order_form<P>(p)},
          sys{&gsl_fixed_rhs<P>, nullptr, static_cast<size_t>(2 * d), &ctx},
          stepper(gsl_odeiv2_step_alloc(Stepper::type(), 2 * d)),
          y(2 * d),
          yerr(2 * d),
          dydt_in(2 * d),
          dydt_out(2 * d) {
      if (!stepper) throw std::runtime_error("gsl_odeiv2_step_alloc failed");
      const auto s0 = p.initial();
      y << s0.x, s0.v;
      gsl_fixed_rhs<P>(0.0, y.data(), dydt_in.data(), &ctx);
    }
    adapter(const adapter&) = delete;  // sys holds &ctx

    void step(double t, double h) {
      const int status =
          gsl_odeiv2_step_apply(stepper.get(), t, h, y.data(), yerr.data(), dydt_in.data(), dydt_out.data(), &sys);
      if (status != GSL_SUCCESS)
        throw std::runtime_error(std::string("gsl_odeiv2_step_apply: ") + gsl_strerror(status));
      dydt_in = dydt_out;
    }
    template <class Vec>
    void state_into(Vec& x, Vec& v) const {
      x = y.head(d);
      v = y.tail(d);
    }
    long force_evals() const { return ctx.calls; }
  };
};

}  // namespace stepbench::peers

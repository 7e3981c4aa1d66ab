// Solutions from GSL's gsl_odeiv2 driver with the y_new error control: the rk8pd
// stepper (Prince-Dormand 8(9), 13 stages) is the reference; rkf45 (Fehlberg 4(5)) is
// a peer that the benchmark times over a ladder of tolerances.
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <cmath>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

#include "references/detail.hpp"
#include "references/reference.hpp"

namespace stepbench {

namespace {

// Every call of f goes through here; GSL itself counts none. GSL_EBADFUNC: evolve_apply
// returns it at once, without retrying.
int gsl_rhs(double t, const double y[], double dydt[], void* params) noexcept {
  return static_cast<detail::callback_state*>(params)->evaluate(t, y, dydt) ? GSL_SUCCESS : GSL_EBADFUNC;
}

struct driver_deleter {
  void operator()(gsl_odeiv2_driver* d) const noexcept { gsl_odeiv2_driver_free(d); }
};

}  // namespace

reference_solution solve_gsl(const ode_system& sys, std::span<const double> times, gsl_method method,
                             reference_tolerances tol) {
  const std::string source = method == gsl_method::rk8pd ? "gsl_rk8pd" : "gsl_rkf45";
  const gsl_odeiv2_step_type* stepper = method == gsl_method::rk8pd ? gsl_odeiv2_step_rk8pd : gsl_odeiv2_step_rkf45;
  return detail::timed_solve(source, sys, times, tol, [&](reference_solution& out) {
    detail::callback_state st;
    st.sys = &sys;
    gsl_odeiv2_system gsys{&gsl_rhs, nullptr, static_cast<std::size_t>(sys.n), &st};

    // A small first step; the control grows it at most 5x per step (cstd.c), so the cost of
    // starting small is a handful of steps, while starting too large costs rejections.
    const double hstart = 1e-6 * times.front();
    std::unique_ptr<gsl_odeiv2_driver, driver_deleter> driver(
        gsl_odeiv2_driver_alloc_y_new(&gsys, stepper, hstart, tol.atol, tol.rtol));
    if (!driver) throw std::runtime_error(source + ": gsl_odeiv2_driver_alloc_y_new returned null");
    // nmax bounds the steps of one driver_apply call (0 would mean unbounded): a problem too
    // stiff for an explicit solver fails in seconds with a message instead of running on.
    if (int s = gsl_odeiv2_driver_set_nmax(driver.get(), static_cast<unsigned long>(sys.max_steps_per_output));
        s != GSL_SUCCESS)
      throw std::runtime_error(source + ": gsl_odeiv2_driver_set_nmax failed, status " + std::to_string(s));

    std::vector<double> y = sys.y0;
    double t = 0.0;
    for (double tout : times) {
      const int status = gsl_odeiv2_driver_apply(driver.get(), &t, tout, y.data());
      if (st.error) std::rethrow_exception(st.error);
      if (st.non_finite)
        throw std::runtime_error(source + ": right-hand side returned a non-finite value at t=" +
                                 detail::num(st.non_finite_t) + " (integrating towards t=" + detail::num(tout) + ")");
      if (status != GSL_SUCCESS)
        throw std::runtime_error(source + ": gsl_odeiv2_driver_apply failed at t=" + detail::num(t) +
                                 " towards t=" + detail::num(tout) + ", status " + std::to_string(status) + " (" +
                                 gsl_strerror(status) + ")");
      for (double v : y)
        if (!std::isfinite(v)) throw std::runtime_error(source + ": non-finite state at t=" + detail::num(tout));
      out.y.push_back(y);
    }

    // Counters of the evolve object (gsl_odeiv2.h), accumulated over all driver_apply calls
    // (driver_apply resets only driver->n). gsl_odeiv2_evolve_apply increments count before
    // the error test, so count is every attempt and a rejected one is in both count and
    // failed_steps (GSL 2.7.1 ode-initval2/evolve.c; checked: driver->n, the accepted steps of
    // one driver_apply, equals the increase of count - failed_steps).
    out.stats.failed_steps = static_cast<long>(driver->e->failed_steps);
    out.stats.steps = static_cast<long>(driver->e->count) - out.stats.failed_steps;
    out.stats.rhs_evals_counted = st.calls;
    out.stats.rhs_evals = st.calls;
  });
}

}  // namespace stepbench

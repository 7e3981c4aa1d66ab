#pragma once
// The adaptive library solvers a user might pick instead: GSL's driver (rkf45, rk8pd),
// SUNDIALS CVODE (Adams, BDF) and ARKODE's explicit Runge-Kutta stepper (ERKStep with its
// default tables of order 8 and 5), over a ladder of tolerances (rtol = atol = tol),
// with output at the sample times. They are the reference solvers' wrappers
// (references/) at the user's tolerance, so each C library is wrapped once.
#include <span>
#include <vector>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/method.hpp"
#include "references/reference.hpp"

namespace stepbench::peers {

// A reference solution in the shape of a run.
template <class Vec>
drive_result<Vec> as_run(const reference_solution& sol, int dim) {
  drive_result<Vec> out;
  out.steps = sol.stats.steps;
  out.rejected_steps = sol.stats.failed_steps;
  out.work.force_evals = sol.stats.rhs_evals_counted;
  out.work.jacobian_evals = sol.stats.jac_evals;
  out.work.newton_iterations = sol.stats.newton_iterations;
  out.work.linear_solves = sol.stats.linear_solves;
  out.start(dim, sol.y.size());
  for (std::size_t j = 0; j < sol.y.size(); ++j) {
    const Eigen::Map<const Eigen::VectorXd> y(sol.y[j].data(), 2 * dim);
    out.record(sol.times[j], y.head(dim), y.tail(dim));
  }
  if (sol.diverged) {  // a fixed-step run that blew up (ARKODE): recorded as diverged
    out.non_finite = true;
    out.final_state = {Vec::Constant(dim, std::numeric_limits<double>::quiet_NaN()),
                       Vec::Constant(dim, std::numeric_limits<double>::quiet_NaN())};
    out.t_final = sol.y.empty() ? 0.0 : sol.times[sol.y.size() - 1];
    return out;
  }
  const Eigen::Map<const Eigen::VectorXd> last(sol.y.back().data(), 2 * dim);
  out.final_state = {last.head(dim), last.tail(dim)};
  out.t_final = sol.times.back();
  return out;
}

template <gsl_method M>
struct gsl_solver {
  static constexpr bool rkf45 = M == gsl_method::rkf45;
  static constexpr const char* name = rkf45 ? "gsl_rkf45_adaptive" : "gsl_rk8pd_adaptive";
  static constexpr const char* description =
      rkf45 ? "GSL driver, rkf45 with y_new control" : "GSL driver, rk8pd with y_new control";
  static constexpr const char* library = "GSL";
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_gsl(s, t, M, {tol, tol});
  }
};
template <cvode_method M>
struct cvode_solver {
  static constexpr bool adams = M == cvode_method::adams;
  static constexpr const char* name = adams ? "cvode_adams" : "cvode_bdf";
  static constexpr const char* description =
      adams ? "CVODE Adams-Moulton, fixed-point iteration"
            : "CVODE BDF, Newton (band solver with the analytic Jacobian for a chain, else dense difference quotients)";
  static constexpr const char* library = "SUNDIALS CVODE";
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_cvode(s, t, M, {tol, tol});
  }
};

// ARKODE ERKStep with its default table of an order (ARKODE_FEHLBERG_13_7_8 for 8,
// ARKODE_CASH_KARP_6_4_5 for 5 in SUNDIALS 6.4), landing on each sample time with
// ERKStepSetStopTime; the order recorded is the table's q as ARKODE loads it.
template <int Order>
struct arkode_erk_solver {
  static constexpr const char* name = Order == 8 ? "arkode_erk8_adaptive" : "arkode_erk5_adaptive";
  static constexpr const char* description = Order == 8
                                                 ? "ARKODE ERKStep, default order-8 table (Fehlberg 7(8), 13 stages)"
                                                 : "ARKODE ERKStep, default order-5 table (Cash-Karp 5(4), 6 stages)";
  static constexpr const char* library = "SUNDIALS ARKODE";
  static double declared_order() { return arkode_erk_default_table(Order).q; }
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_arkode_erk(s, t, Order, {tol, tol});
  }
};

template <class Solver>
struct library_adaptive {
  static method_info info() {
    double order = std::numeric_limits<double>::quiet_NaN();
    if constexpr (requires { Solver::declared_order(); }) order = Solver::declared_order();
    return {.name = Solver::name,
            .description = Solver::description,
            .origin = method_origin::peer,
            .kind = method_kind::adaptive,
            .declared_order = order,
            .traits = {.error_estimate = true},
            .library = Solver::library};
  }

  // The right-hand side is wrapped once; each run is the solver's whole run (set-up,
  // integration, output at the sample times), as a user would call it.
  template <problem P>
  static auto prepare(const P& p, double tol, double /*horizon*/, std::span<const double> times, const run_limits&) {
    return [sys = make_ode_system(p), dim = p.dim(), tol, t = std::vector<double>(times.begin(), times.end())] {
      return as_run<typename P::vec>(Solver::solve(sys, t, tol), dim);
    };
  }
};

}  // namespace stepbench::peers

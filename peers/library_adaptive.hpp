#pragma once
// The adaptive library solvers a user might pick instead: GSL's driver (rkf45, rk8pd)
// and SUNDIALS CVODE (Adams, BDF), over a ladder of tolerances (rtol = atol = tol),
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
  const Eigen::Map<const Eigen::VectorXd> last(sol.y.back().data(), 2 * dim);
  out.final_state = {last.head(dim), last.tail(dim)};
  out.t_final = sol.times.back();
  return out;
}

struct gsl_rkf45_solver {
  static constexpr const char* name = "gsl_rkf45_adaptive";
  static constexpr const char* description = "GSL driver, rkf45 with y_new control";
  static constexpr const char* library = "GSL";
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_gsl(s, t, gsl_method::rkf45, {tol, tol});
  }
};
struct gsl_rk8pd_solver {
  static constexpr const char* name = "gsl_rk8pd_adaptive";
  static constexpr const char* description = "GSL driver, rk8pd with y_new control";
  static constexpr const char* library = "GSL";
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_gsl(s, t, gsl_method::rk8pd, {tol, tol});
  }
};
struct cvode_adams_solver {
  static constexpr const char* name = "cvode_adams";
  static constexpr const char* description = "CVODE Adams-Moulton, fixed-point iteration";
  static constexpr const char* library = "SUNDIALS CVODE";
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_cvode(s, t, cvode_method::adams, {tol, tol});
  }
};
struct cvode_bdf_solver {
  static constexpr const char* name = "cvode_bdf";
  static constexpr const char* description =
      "CVODE BDF, Newton (band solver with the analytic Jacobian for a chain, else dense difference quotients)";
  static constexpr const char* library = "SUNDIALS CVODE";
  static reference_solution solve(const ode_system& s, std::span<const double> t, double tol) {
    return solve_cvode(s, t, cvode_method::bdf, {tol, tol});
  }
};

template <class Solver>
struct library_adaptive {
  static method_info info() {
    return {Solver::name, Solver::description, method_origin::peer, method_kind::adaptive,
            std::numeric_limits<double>::quiet_NaN(), {.error_estimate = true}, Solver::library};
  }
  template <problem P>
  static constexpr bool applies = true;

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

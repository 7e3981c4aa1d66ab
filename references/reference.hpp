#pragma once
// Reference solutions from GSL (gsl_odeiv2) and SUNDIALS CVODE.
//
// The references see a problem as the first-order system y' = f(t, y) with
// y = [x; v] and f = [v; F(t, x, v) / m]. They are not in the hot loop of anything we
// time, so the right-hand side goes through std::function here: type erasure at the
// edge, as the style asks.
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace stepbench {

struct ode_system {
  int n = 0;  // first-order dimension, 2 * (spatial dimension)
  std::vector<double> y0;
  // dydt = f(t, y); both spans have length n.
  std::function<void(double t, std::span<const double> y, std::span<double> dydt)> rhs;
  // Step budget between two output times: a problem too stiff or too large for a
  // solver fails in bounded time with the solver's message (the caller scales it with
  // the problem's size and stiffness: study/registry.cpp, reference_step_budget).
  long max_steps_per_output = 200'000;
  // Optional, for the stiff solver (CVODE BDF): the force Jacobians of a second-order
  // system y = [x; v], f = [v; F(t, x, v) / m] with n / 2 coordinates. force_jacobian(t,
  // y, emit) calls emit(i, j, dF_i/dx_j / m, dF_i/dv_j / m) for every pair of coordinates
  // with |i - j| <= coupling_bandwidth (the rest are zero). -1: not given.
  int coupling_bandwidth = -1;
  using jacobian_entry = std::function<void(int i, int j, double dfdx_over_m, double dfdv_over_m)>;
  std::function<void(double t, std::span<const double> y, const jacobian_entry& emit)> force_jacobian;
};

// What a reference solver did to produce its solution. Every count is the solver's
// own, except rhs_evals for GSL, which counts no right-hand-side calls: we wrap the
// callback and count there.
struct reference_stats {
  long steps = 0;          // accepted steps
  long failed_steps = 0;   // rejected step attempts (error test and, for CVODE, convergence failures)
  long rhs_evals = 0;      // calls of f made by the integrator proper (CVodeGetNumRhsEvals for CVODE)
  long lin_rhs_evals = 0;  // CVODE only: calls of f for the difference-quotient Jacobian (CVodeGetNumLinRhsEvals)
  long jac_evals = 0;      // CVODE only: Jacobian evaluations (CVodeGetNumJacEvals)
  long newton_iterations = 0;  // CVODE BDF: Newton iterations (CVodeGetNumNonlinSolvIters)
  long linear_solves = 0;      // CVODE BDF: linear solves, one per Newton iteration with a direct solver
  long rhs_evals_counted = 0;  // our own count of every call of f, from a wrapped callback
  double rtol = 0.0;
  double atol = 0.0;
  double wall_seconds = 0.0;
};

struct reference_solution {
  std::string source;  // "gsl_rk8pd", "cvode_bdf", "cvode_adams"
  std::vector<double> times;            // the requested output times, increasing, > 0
  std::vector<std::vector<double>> y;   // y[i] is the state (size n) at times[i]
  reference_stats stats;
};

// Tight enough that CVODE BDF, the least accurate of the three at a given tolerance
// (max order 5), still agrees with the closed forms to better than 1e-9 relative; not
// so tight that CVODE refuses it (its floor is about 100 eps).
struct reference_tolerances {
  double rtol = 1e-13;
  double atol = 1e-14;
};

// Integrates from t = 0 to each of `times` (increasing, all > 0) and returns the state
// there. Throws std::runtime_error, with the failing call and its return code, on any
// solver failure.
reference_solution solve_gsl_rk8pd(const ode_system& sys, std::span<const double> times,
                                   reference_tolerances tol = {});

// The same driver with another embedded stepper (rkf45 is a peer, not a reference).
enum class gsl_method { rk8pd, rkf45 };
reference_solution solve_gsl(const ode_system& sys, std::span<const double> times, gsl_method method,
                             reference_tolerances tol = {});

// CVODE: BDF with Newton iterations (a band linear solver with the problem's analytic
// Jacobian when the system gives a banded one, else a dense difference-quotient
// Jacobian), or Adams with fixed-point iterations.
enum class cvode_method { bdf, adams };
reference_solution solve_cvode(const ode_system& sys, std::span<const double> times, cvode_method method,
                               reference_tolerances tol = {});

// ARKODE's explicit Runge-Kutta stepper (ERKStep) with its default table of the given
// order (8: ARKODE_FEHLBERG_13_7_8; 5: ARKODE_DORMAND_PRINCE_7_4_5).
reference_solution solve_arkode_erk(const ode_system& sys, std::span<const double> times, int order,
                                    reference_tolerances tol = {});

// The reference sources by name, in the order they are reported.
inline constexpr const char* reference_sources[] = {"gsl_rk8pd", "cvode_bdf", "cvode_adams", "arkode_erk8"};
reference_solution solve_reference(std::string_view source, const ode_system& sys, std::span<const double> times,
                                   reference_tolerances tol = {});

}  // namespace stepbench

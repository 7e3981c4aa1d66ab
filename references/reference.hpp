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

enum class cvode_method { bdf, adams };
reference_solution solve_cvode(const ode_system& sys, std::span<const double> times, cvode_method method,
                               reference_tolerances tol = {});

// The reference sources by name, in the order they are reported.
inline constexpr const char* reference_sources[] = {"gsl_rk8pd", "cvode_bdf", "cvode_adams"};
reference_solution solve_reference(std::string_view source, const ode_system& sys, std::span<const double> times,
                                   reference_tolerances tol = {});

}  // namespace stepbench

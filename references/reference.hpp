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
  // the problem's size and stiffness: core/first_order.hpp, reference_step_budget).
  long max_steps_per_output = 200'000;
  // Optional, for the stiff solver (CVODE BDF): the force Jacobians of a second-order
  // system y = [x; v], f = [v; F(t, x, v) / m] with n / 2 coordinates. force_jacobian(t,
  // y, emit) calls emit(i, j, dF_i/dx_j / m, dF_i/dv_j / m) for every pair of coordinates
  // with |i - j| <= coupling_bandwidth (the rest are zero). -1: not given.
  int coupling_bandwidth = -1;
  using jacobian_entry = std::function<void(int i, int j, double dfdx_over_m, double dfdv_over_m)>;
  std::function<void(double t, std::span<const double> y, const jacobian_entry& emit)> force_jacobian;
  // Optional: contacts (a ground plane, walls, other bodies). contact_gap(t, y) is the
  // smallest signed distance of the contacts (< 0: penetrated); resolve_contacts(t, y)
  // applies the problem's response in place and returns the number of contacts it
  // resolved. Only CVODE's wrapper handles them (root finding, CVodeRootInit); the other
  // references refuse such a system (reference_handles_contacts).
  std::function<double(double t, std::span<const double> y)> contact_gap;
  std::function<int(double t, std::span<double> y)> resolve_contacts;
  bool has_contacts() const { return static_cast<bool>(contact_gap); }
};

// What a reference solver did to produce its solution. Every count is the solver's
// own, except rhs_evals for GSL, which counts no right-hand-side calls: we wrap the
// callback and count there.
struct reference_stats {
  long steps = 0;              // accepted steps
  long failed_steps = 0;       // rejected step attempts (error test and, for CVODE, convergence failures)
  long rhs_evals = 0;          // calls of f made by the integrator proper (CVodeGetNumRhsEvals for CVODE)
  long lin_rhs_evals = 0;      // CVODE only: calls of f for the difference-quotient Jacobian (CVodeGetNumLinRhsEvals)
  long jac_evals = 0;          // CVODE only: Jacobian evaluations (CVodeGetNumJacEvals)
  long newton_iterations = 0;  // CVODE BDF: Newton iterations (CVodeGetNumNonlinSolvIters)
  long linear_solves = 0;      // CVODE BDF: linear solves, one per Newton iteration with a direct solver
  long rhs_evals_counted = 0;  // our own count of every call of f, from a wrapped callback
  double rtol = 0.0;
  double atol = 0.0;
  double wall_seconds = 0.0;
};

struct reference_solution {
  std::string source;                  // "gsl_rk8pd", "cvode_bdf", "cvode_adams"
  std::vector<double> times;           // the requested output times, increasing, > 0
  std::vector<std::vector<double>> y;  // y[i] is the state (size n) at times[i]
  reference_stats stats;
  long contacts = 0;  // roots of the contact gap at which a response was applied (CVODE with contacts)
  // Fixed-step runs only (solve_arkode_erk with a fixed step): the solution became
  // non-finite (the step is beyond the method's stability limit), so the run stopped with
  // the output times reached before; y is shorter than times. Adaptive runs throw instead.
  bool diverged = false;
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
// solver failure. GSL's driver with its rk8pd stepper (the reference) or rkf45 (a peer).
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
// order (8: ARKODE_FEHLBERG_13_7_8; 5: ARKODE_DORMAND_PRINCE_7_4_5). With fixed_step > 0
// the steps are that size (ERKStepSetFixedStep; no error test), shortened only to land
// on each output time (ERKStepSetStopTime); the tolerances are then unused.
reference_solution solve_arkode_erk(const ode_system& sys, std::span<const double> times, int order,
                                    reference_tolerances tol = {}, double fixed_step = 0.0);

// The default ERKStep table of an order, as ARKODE loads it: its name, its stage count,
// the order q of the method and p of its embedding (ARKodeButcherTable_LoadERK).
struct arkode_erk_table_info {
  std::string name;
  int stages = 0;
  int q = 0;
  int p = 0;
};
arkode_erk_table_info arkode_erk_default_table(int order);

// Whether a reference source handles a system's contacts (CVODE's root finding), so that
// the truth builder runs only those on a problem with contacts.
bool reference_handles_contacts(std::string_view source);

// The reference sources by name, in the order they are reported.
inline constexpr const char* reference_sources[] = {"gsl_rk8pd", "cvode_bdf", "cvode_adams", "arkode_erk8"};
reference_solution solve_reference(std::string_view source, const ode_system& sys, std::span<const double> times,
                                   reference_tolerances tol = {});

}  // namespace stepbench

#pragma once
// Shared by the GSL, CVODE and ARKODE wrappers; not part of the interface (reference.hpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <span>
#include <string>
#include <string_view>

#include "references/reference.hpp"

namespace stepbench::detail {

// A time or value for an error message: %g, not std::to_string's fixed notation.
inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Both solvers are public, so both check their input, not only solve_reference.
void validate_reference_input(std::string_view source, const ode_system& sys, std::span<const double> times,
                              reference_tolerances tol);

// The frame of every wrapper: checks the input, then times solve(out), which fills the
// states and the counters; the source, the output times and the tolerances are filled
// here, so that every solver gives the same record.
template <class Solve>
reference_solution timed_solve(std::string_view source, const ode_system& sys, std::span<const double> times,
                               reference_tolerances tol, Solve&& solve) {
  validate_reference_input(source, sys, times, tol);
  const auto start = std::chrono::steady_clock::now();
  reference_solution out;
  out.source = source;
  out.times.assign(times.begin(), times.end());
  out.y.reserve(times.size());
  solve(out);
  out.stats.rtol = tol.rtol;
  out.stats.atol = tol.atol;
  out.stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

// What a C callback needs, and what it hands back: a C++ exception must not cross the
// library's C frames, so it is stashed and rethrown once the library has returned; a
// non-finite derivative is recorded with its time.
struct callback_state {
  const ode_system* sys = nullptr;
  long calls = 0;
  std::exception_ptr error;
  bool non_finite = false;
  double non_finite_t = 0.0;
  std::string last_message;  // SUNDIALS' error handler's, instead of its printing to stderr

  // The system's f(t, y) into dydt, for a library callback, counting every call: false
  // when it threw (the exception is stashed) or gave a non-finite derivative (recorded
  // with its time). A reference must never silently return NaN, and a non-finite
  // derivative is a broken model, not a step that is too large: each callback then
  // returns its library's unrecoverable failure, so the library stops at once rather than
  // shrinking the step towards the bad point (GSL's y_new control would even accept a NaN
  // error ratio: GSL 2.7.1 ode-initval2/cstd.c takes rmax = GSL_MAX_DBL(r, rmax), which
  // drops a NaN). Once failed, every later call fails too: SUNDIALS 6.4.1's fixed-point
  // solver (CVODE's Adams) turns an unrecoverable -1 into a recoverable convergence
  // failure (seen here: CVODE then shrinks the step towards the bad point until mxstep,
  // ~10^7 steps); failing every attempt makes CVODE stop after MXNCF = 10 consecutive
  // failures instead.
  bool evaluate(double t, std::span<const double> y, std::span<double> dydt) noexcept {
    ++calls;
    if (non_finite || !guarded([&] { sys->rhs(t, y, dydt); })) return false;
    for (const double d : dydt)
      if (!std::isfinite(d)) {
        non_finite = true;
        non_finite_t = t;
        return false;
      }
    return true;
  }
  bool evaluate(double t, const double* y, double* dydt) noexcept {
    const auto n = static_cast<std::size_t>(sys->n);
    return evaluate(t, std::span<const double>(y, n), std::span<double>(dydt, n));
  }

  // f() inside a library callback: false when an earlier callback failed or f throws (the
  // exception is stashed).
  template <class F>
  bool guarded(F&& f) noexcept {
    if (error) return false;
    try {
      f();
    } catch (...) {
      error = std::current_exception();
      return false;
    }
    return true;
  }

  // "<source>: <call> failed, flag <flag> (<name>)" and what the callbacks saw.
  std::string failure(std::string_view source, std::string_view call, int flag, std::string_view name) const {
    std::string what = std::string(source) + ": " + std::string(call) + " failed, flag " + std::to_string(flag) + " (" +
                       std::string(name) + ")";
    if (non_finite) what += "; right-hand side returned a non-finite value at t=" + num(non_finite_t);
    if (!last_message.empty()) what += "; " + last_message;
    return what;
  }
};

// The name of a SUNDIALS return flag from one of its name functions (CVodeGetReturnFlagName
// and the like), which return a malloc'd string the caller frees (cvode_io.c, arkode_io.c).
inline std::string sundials_flag_name(char* name) {
  std::string s = name ? name : "?";
  std::free(name);
  return s;
}

// SUNDIALS' error handler (CVodeSetErrHandlerFn, ERKStepSetErrHandlerFn): keeps the
// message for the exception the wrapper throws; warnings (code `Warning`) are dropped.
template <class State, int Warning>
void keep_sundials_message(int error_code, const char* module, const char* function, char* msg,
                           void* user_data) noexcept {
  if (error_code == Warning) return;
  static_cast<State*>(user_data)->last_message = std::string(module) + "/" + function + ": " + msg;
}

}  // namespace stepbench::detail

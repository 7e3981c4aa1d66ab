// Reference solutions from SUNDIALS CVODE 6.x: BDF with Newton iteration on a dense
// difference-quotient Jacobian, or Adams with fixed-point (functional) iteration.
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>

#include "references/detail.hpp"
#include "references/reference.hpp"

namespace stepbench {

namespace {

struct cvode_callback_state : detail::callback_state {
  std::string last_message;  // from the error handler, instead of CVODE printing to stderr
};

// Every call of f, including those of the difference-quotient Jacobian, goes through here.
int cvode_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) noexcept {
  auto& st = *static_cast<cvode_callback_state*>(user_data);
  ++st.calls;
  // Once failed, fail every later call too. SUNDIALS 6.4.1's fixed-point solver (Adams) turns
  // our unrecoverable -1 into a recoverable convergence failure (seen here: CVODE then shrinks
  // the step towards the bad point until mxstep, ~10^7 steps). Failing every attempt makes
  // CVODE stop after MXNCF = 10 consecutive failures instead.
  if (st.error || st.non_finite) return -1;
  const auto n = static_cast<std::size_t>(st.sys->n);
  double* dydt = N_VGetArrayPointer(ydot);
  try {
    st.sys->rhs(t, std::span<const double>(N_VGetArrayPointer(y), n), std::span<double>(dydt, n));
  } catch (...) {
    st.error = std::current_exception();
    return -1;  // negative: unrecoverable, CVODE stops (user guide 6.x, CVRhsFn)
  }
  // A non-finite derivative is a broken model, not a step that is too large: fail at once
  // (unrecoverable) rather than let CVODE shrink the step towards the bad point.
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(dydt[i])) {
      st.non_finite = true;
      st.non_finite_t = t;
      return -1;
    }
  }
  return 0;
}

// Replaces CVODE's default handler, which prints to stderr; the message goes into the
// exception instead (CVodeSetErrHandlerFn, user guide 6.x).
void cvode_error_handler(int error_code, const char* module, const char* function, char* msg,
                         void* user_data) noexcept {
  if (error_code == CV_WARNING) return;
  auto& st = *static_cast<cvode_callback_state*>(user_data);
  st.last_message = std::string(module) + "/" + function + ": " + msg;
}

// Owns every SUNDIALS handle; members are freed in reverse order of creation on every path.
struct cvode_handles {
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  SUNMatrix a = nullptr;
  SUNLinearSolver ls = nullptr;
  SUNNonlinearSolver nls = nullptr;
  void* mem = nullptr;

  cvode_handles() = default;
  cvode_handles(const cvode_handles&) = delete;
  cvode_handles& operator=(const cvode_handles&) = delete;
  ~cvode_handles() {
    // CVODE does not own a linear or nonlinear solver attached by the user.
    if (mem) CVodeFree(&mem);
    if (nls) SUNNonlinSolFree(nls);
    if (ls) SUNLinSolFree(ls);
    if (a) SUNMatDestroy(a);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }
};

// Which family of return codes a call uses: CVODE's CV_*, the linear solver interface's
// CVLS_*, or another SUNDIALS code without a name function.
enum class flag_kind { cv, cvls, other };

std::string flag_name(int flag, flag_kind kind) {
  if (kind == flag_kind::other) return "see SUNDIALS docs";
  // Both name functions return a malloc'd string the caller frees (cvode_io.c, cvode_ls.c).
  char* name = kind == flag_kind::cv ? CVodeGetReturnFlagName(flag) : CVodeGetLinReturnFlagName(flag);
  std::string s = name ? name : "?";
  std::free(name);
  return s;
}

}  // namespace

reference_solution solve_cvode(const ode_system& sys, std::span<const double> times, cvode_method method,
                               reference_tolerances tol) {
  const char* source = method == cvode_method::bdf ? "cvode_bdf" : "cvode_adams";
  detail::validate_reference_input(source, sys, times, tol);
  const auto start = std::chrono::steady_clock::now();

  cvode_callback_state st;
  st.sys = &sys;
  cvode_handles h;
  const auto fail = [&](const std::string& call, int flag, flag_kind kind = flag_kind::cv) {
    std::string what = std::string(source) + ": " + call + " failed, flag " + std::to_string(flag) + " (" +
                       flag_name(flag, kind) + ")";
    if (st.non_finite) what += "; right-hand side returned a non-finite value at t=" + detail::num(st.non_finite_t);
    if (!st.last_message.empty()) what += "; " + st.last_message;
    throw std::runtime_error(what);
  };
  const auto check = [&](const char* call, int flag, flag_kind kind = flag_kind::cv) {
    if (flag != 0) fail(call, flag, kind);
  };
  const auto check_ptr = [&](const char* call, const void* p) {
    if (!p) throw std::runtime_error(std::string(source) + ": " + call + " returned null");
  };

  check("SUNContext_Create", SUNContext_Create(nullptr, &h.ctx), flag_kind::other);
  h.y = N_VNew_Serial(sys.n, h.ctx);
  check_ptr("N_VNew_Serial", h.y);
  std::copy(sys.y0.begin(), sys.y0.end(), N_VGetArrayPointer(h.y));

  h.mem = CVodeCreate(method == cvode_method::bdf ? CV_BDF : CV_ADAMS, h.ctx);
  check_ptr("CVodeCreate", h.mem);
  check("CVodeSetErrHandlerFn", CVodeSetErrHandlerFn(h.mem, &cvode_error_handler, &st));
  check("CVodeInit", CVodeInit(h.mem, &cvode_rhs, 0.0, h.y));
  check("CVodeSStolerances", CVodeSStolerances(h.mem, tol.rtol, tol.atol));
  check("CVodeSetUserData", CVodeSetUserData(h.mem, &st));
  check("CVodeSetMaxNumSteps", CVodeSetMaxNumSteps(h.mem, detail::max_steps_per_output));

  if (method == cvode_method::bdf) {
    // No Jacobian function is set, so CVLS uses its dense difference-quotient Jacobian,
    // whose n calls of f per evaluation count in CVodeGetNumLinRhsEvals, not in nfe.
    h.a = SUNDenseMatrix(sys.n, sys.n, h.ctx);
    check_ptr("SUNDenseMatrix", h.a);
    h.ls = SUNLinSol_Dense(h.y, h.a, h.ctx);
    check_ptr("SUNLinSol_Dense", h.ls);
    check("CVodeSetLinearSolver", CVodeSetLinearSolver(h.mem, h.ls, h.a), flag_kind::cvls);
  } else {
    // Adams is for non-stiff problems: functional iteration, no linear solver (m = 0: no
    // Anderson acceleration).
    h.nls = SUNNonlinSol_FixedPoint(h.y, 0, h.ctx);
    check_ptr("SUNNonlinSol_FixedPoint", h.nls);
    check("CVodeSetNonlinearSolver", CVodeSetNonlinearSolver(h.mem, h.nls));
  }

  reference_solution out;
  out.source = source;
  out.times.assign(times.begin(), times.end());
  out.y.reserve(times.size());

  const auto n = static_cast<std::size_t>(sys.n);
  for (double tout : times) {
    // CV_NORMAL: CVODE steps past tout and interpolates its Nordsieck history there, which
    // is accurate to the integration tolerance (user guide 6.x, CVode).
    sunrealtype t = 0.0;
    const int flag = CVode(h.mem, tout, h.y, &t, CV_NORMAL);
    if (st.error) std::rethrow_exception(st.error);
    if (flag < 0) fail("CVode at t=" + detail::num(t) + " towards t=" + detail::num(tout), flag);
    const double* y = N_VGetArrayPointer(h.y);
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(y[i])) throw std::runtime_error(std::string(source) + ": non-finite state at t=" +
                                                         detail::num(tout));
    out.y.emplace_back(y, y + n);
  }

  auto& s = out.stats;
  long err_fails = 0, solve_fails = 0;
  check("CVodeGetNumSteps", CVodeGetNumSteps(h.mem, &s.steps));
  check("CVodeGetNumErrTestFails", CVodeGetNumErrTestFails(h.mem, &err_fails));
  // Since SUNDIALS 6.2 CVodeGetNumNonlinSolvConvFails counts every nonlinear solver failure,
  // including ones recovered by a Jacobian update within the same attempt; the failed step
  // attempts are CVodeGetNumStepSolveFails (SUNDIALS changelog, release 6.2.0).
  check("CVodeGetNumStepSolveFails", CVodeGetNumStepSolveFails(h.mem, &solve_fails));
  s.failed_steps = err_fails + solve_fails;
  check("CVodeGetNumRhsEvals", CVodeGetNumRhsEvals(h.mem, &s.rhs_evals));
  if (method == cvode_method::bdf) {
    check("CVodeGetNumLinRhsEvals", CVodeGetNumLinRhsEvals(h.mem, &s.lin_rhs_evals), flag_kind::cvls);
    check("CVodeGetNumJacEvals", CVodeGetNumJacEvals(h.mem, &s.jac_evals), flag_kind::cvls);
  }
  s.rhs_evals_counted = st.calls;
  s.rtol = tol.rtol;
  s.atol = tol.atol;
  s.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace stepbench

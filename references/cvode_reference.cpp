// Reference solutions from SUNDIALS CVODE 6.x: BDF with Newton iteration, or Adams with
// fixed-point (functional) iteration. BDF's linear solver: when the system gives a
// banded force Jacobian (a chain), CVODE gets the analytic Jacobian and a band solver,
// with the state interleaved per coordinate ([x_0, v_0, x_1, v_1, ...]) so that the
// first-order Jacobian [[0, I], [dF/dx, dF/dv] / m] is banded too (half-bandwidth
// 2 b + 1 for a force coupling b neighbouring coordinates); otherwise a dense
// difference-quotient Jacobian, as good for a few coordinates.
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>

#include "references/detail.hpp"
#include "references/reference.hpp"

namespace stepbench {

namespace {

struct cvode_callback_state : detail::callback_state {
  // Interleaved layout (band solver): CVODE's y[2c] = x_c, y[2c+1] = v_c; the system's
  // own layout is [x; v]. These hold the system's view.
  bool interleaved = false;
  std::vector<double> y_plain, dydt_plain;

  // CVODE's vector to the system's [x; v] layout (identity when not interleaved).
  std::span<const double> plain(const double* y) {
    const auto n = static_cast<std::size_t>(sys->n);
    if (!interleaved) return {y, n};
    const std::size_t dim = n / 2;
    for (std::size_t c = 0; c < dim; ++c) y_plain[c] = y[2 * c], y_plain[dim + c] = y[2 * c + 1];
    return y_plain;
  }
};

// The system's [x; v] layout to CVODE's.
void to_solver_layout(const cvode_callback_state& st, std::span<const double> plain, double* out) {
  const std::size_t n = plain.size(), dim = n / 2;
  if (!st.interleaved) {
    std::copy(plain.begin(), plain.end(), out);
    return;
  }
  for (std::size_t c = 0; c < dim; ++c) out[2 * c] = plain[c], out[2 * c + 1] = plain[dim + c];
}

// Every call of f, including those of the difference-quotient Jacobian, goes through here.
// A failure is unrecoverable: negative, CVODE stops (user guide 6.x, CVRhsFn).
int cvode_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) noexcept {
  auto& st = *static_cast<cvode_callback_state*>(user_data);
  double* dydt = N_VGetArrayPointer(ydot);
  if (!st.interleaved) return st.evaluate(t, N_VGetArrayPointer(y), dydt) ? 0 : -1;
  if (!st.evaluate(t, st.plain(N_VGetArrayPointer(y)), st.dydt_plain)) return -1;
  to_solver_layout(st, st.dydt_plain, dydt);
  return 0;
}

// The first-order Jacobian in the interleaved layout: d(x_c)'/d(v_c) = 1,
// d(v_i)'/d(x_j) = dF_i/dx_j / m, d(v_i)'/d(v_j) = dF_i/dv_j / m (CVLsJacFn, user guide 6.x).
int cvode_band_jacobian(sunrealtype t, N_Vector y, N_Vector, SUNMatrix jac, void* user_data, N_Vector, N_Vector,
                        N_Vector) noexcept {
  auto& st = *static_cast<cvode_callback_state*>(user_data);
  const bool ok = st.guarded([&] {
    SUNMatZero(jac);
    const std::size_t dim = static_cast<std::size_t>(st.sys->n) / 2;
    for (std::size_t c = 0; c < dim; ++c) SM_ELEMENT_B(jac, 2 * c, 2 * c + 1) = 1.0;
    st.sys->force_jacobian(t, st.plain(N_VGetArrayPointer(y)), [&](int i, int j, double kx, double kv) {
      SM_ELEMENT_B(jac, 2 * i + 1, 2 * j) = kx;
      SM_ELEMENT_B(jac, 2 * i + 1, 2 * j + 1) = kv;
    });
  });
  return ok ? 0 : -1;
}

// The contact gap as CVODE's root function (CVRootFn, user guide 6.x): one root, the
// smallest signed distance of the problem's contacts.
int cvode_contact_root(sunrealtype t, N_Vector y, sunrealtype* gout, void* user_data) noexcept {
  auto& st = *static_cast<cvode_callback_state*>(user_data);
  return st.guarded([&] { gout[0] = st.sys->contact_gap(t, st.plain(N_VGetArrayPointer(y))); }) ? 0 : -1;
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

// The name function of a call's family of return codes: CVODE's CV_* (the default), the
// linear solver interface's CVLS_* (CVodeGetLinReturnFlagName), or none for another
// SUNDIALS code.
using flag_namer = char* (*)(long int);

// One CVODE solve, in the stages a reader of the user guide expects: create and
// initialise, attach the linear or nonlinear solver, enable root finding at contacts,
// advance to each output time, read the counters. Every SUNDIALS call is checked and a
// failure thrown as one line naming the call, its flag and what the callbacks saw.
class cvode_session {
 public:
  cvode_session(const ode_system& sys, cvode_method method)
      : sys_(sys), method_(method), source_(method == cvode_method::bdf ? "cvode_bdf" : "cvode_adams") {
    st_.sys = &sys;
  }
  const char* source() const { return source_; }

  void create(reference_tolerances tol) {
    st_.interleaved = banded();
    if (st_.interleaved)
      st_.y_plain.resize(static_cast<std::size_t>(sys_.n)), st_.dydt_plain.resize(static_cast<std::size_t>(sys_.n));
    check("SUNContext_Create", SUNContext_Create(nullptr, &h_.ctx), nullptr);
    h_.y = N_VNew_Serial(sys_.n, h_.ctx);
    check_ptr("N_VNew_Serial", h_.y);
    to_solver_layout(st_, sys_.y0, N_VGetArrayPointer(h_.y));
    h_.mem = CVodeCreate(method_ == cvode_method::bdf ? CV_BDF : CV_ADAMS, h_.ctx);
    check_ptr("CVodeCreate", h_.mem);
    check("CVodeSetErrHandlerFn",
          CVodeSetErrHandlerFn(h_.mem, &detail::keep_sundials_message<cvode_callback_state, CV_WARNING>, &st_));
    check("CVodeInit", CVodeInit(h_.mem, &cvode_rhs, 0.0, h_.y));
    check("CVodeSStolerances", CVodeSStolerances(h_.mem, tol.rtol, tol.atol));
    check("CVodeSetUserData", CVodeSetUserData(h_.mem, &st_));
    check("CVodeSetMaxNumSteps", CVodeSetMaxNumSteps(h_.mem, sys_.max_steps_per_output));
  }

  void attach_solver() {
    if (st_.interleaved) {
      const sunindextype half = 2 * sys_.coupling_bandwidth + 1;
      h_.a = SUNBandMatrix(sys_.n, half, half, h_.ctx);
      check_ptr("SUNBandMatrix", h_.a);
      h_.ls = SUNLinSol_Band(h_.y, h_.a, h_.ctx);
      check_ptr("SUNLinSol_Band", h_.ls);
      check("CVodeSetLinearSolver", CVodeSetLinearSolver(h_.mem, h_.ls, h_.a), &CVodeGetLinReturnFlagName);
      check("CVodeSetJacFn", CVodeSetJacFn(h_.mem, &cvode_band_jacobian), &CVodeGetLinReturnFlagName);
    } else if (method_ == cvode_method::bdf) {
      // No Jacobian function is set, so CVLS uses its dense difference-quotient Jacobian,
      // whose n calls of f per evaluation count in CVodeGetNumLinRhsEvals, not in nfe.
      h_.a = SUNDenseMatrix(sys_.n, sys_.n, h_.ctx);
      check_ptr("SUNDenseMatrix", h_.a);
      h_.ls = SUNLinSol_Dense(h_.y, h_.a, h_.ctx);
      check_ptr("SUNLinSol_Dense", h_.ls);
      check("CVodeSetLinearSolver", CVodeSetLinearSolver(h_.mem, h_.ls, h_.a), &CVodeGetLinReturnFlagName);
    } else {
      // Adams is for non-stiff problems: functional iteration, no linear solver (m = 0: no
      // Anderson acceleration).
      h_.nls = SUNNonlinSol_FixedPoint(h_.y, 0, h_.ctx);
      check_ptr("SUNNonlinSol_FixedPoint", h_.nls);
      check("CVodeSetNonlinearSolver", CVodeSetNonlinearSolver(h_.mem, h_.nls));
    }
  }

  // Contacts: CVODE finds the root of the gap (decreasing crossings only). It sees a
  // contact only where the gap changes sign between two step ends, so a glancing contact
  // whose overlap is shorter than a step (two balls grazing at 6.5 m/s relative speed
  // overlap for about 4.5 ms, where steps had grown to 48 ms) would pass unseen: on a
  // problem with contacts the step is capped at 1 ms.
  static constexpr double contact_max_step = 1e-3;  // [s]
  void enable_contacts() {
    if (!sys_.has_contacts()) return;
    check("CVodeRootInit", CVodeRootInit(h_.mem, 1, &cvode_contact_root));
    int direction = -1;
    check("CVodeSetRootDirection", CVodeSetRootDirection(h_.mem, &direction));
    check("CVodeSetMaxStep", CVodeSetMaxStep(h_.mem, contact_max_step));
  }

  // The state at tout, in the system's layout. At a contact CVODE returns there
  // (CV_ROOT_RETURN), the problem's response is applied to the state, and CVODE starts
  // afresh from it (CVodeReInit: the solution's derivative jumps, so no history carries
  // over). ReInit resets CVODE's counters, so they are summed over the segments.
  std::span<const double> advance(double tout) {
    constexpr long max_contacts = 100000;  // a Zeno sequence (a ball coming to rest) stops here with a message
    // CV_NORMAL: CVODE steps past tout and interpolates its Nordsieck history there, which
    // is accurate to the integration tolerance (user guide 6.x, CVode).
    sunrealtype t = 0.0;
    int flag = CVode(h_.mem, tout, h_.y, &t, CV_NORMAL);
    while (flag == CV_ROOT_RETURN) {
      if (st_.error) std::rethrow_exception(st_.error);
      if (++roots_ > max_contacts)
        throw std::runtime_error(std::string(source_) + ": more than " + std::to_string(max_contacts) +
                                 " contacts before t=" + detail::num(tout) + " (a Zeno sequence?)");
      const auto y = st_.plain(N_VGetArrayPointer(h_.y));
      const double gap = sys_.contact_gap(t, y);  // of the state CVODE would go on from
      y_resolved_.assign(y.begin(), y.end());
      if (const int resolved = sys_.resolve_contacts(t, y_resolved_); resolved > 0) {
        contacts_ += resolved;
        to_solver_layout(st_, y_resolved_, N_VGetArrayPointer(h_.y));
        add_counters(before_reinit_);
        check("CVodeReInit", CVodeReInit(h_.mem, t, h_.y));
      } else if (gap < 0.0) {
        // A root the problem did not resolve, with the bodies already overlapping: the
        // one gap function would stay negative and hide every later contact. The response
        // leaves a body that does not approach (a body resting or sliding on a wall).
        throw std::runtime_error(std::string(source_) + ": a contact at t=" + detail::num(t) +
                                 " that the problem did not resolve (the gap stays negative): a body resting or "
                                 "sliding on a wall is a lasting contact, which root location cannot follow");
      }
      flag = CVode(h_.mem, tout, h_.y, &t, CV_NORMAL);
    }
    if (st_.error) std::rethrow_exception(st_.error);
    if (flag < 0) fail("CVode at t=" + detail::num(t) + " towards t=" + detail::num(tout), flag);
    const auto y = st_.plain(N_VGetArrayPointer(h_.y));
    if (!std::all_of(y.begin(), y.end(), [](double v) { return std::isfinite(v); }))
      throw std::runtime_error(std::string(source_) + ": non-finite state at t=" + detail::num(tout));
    // Root location sees a contact where the gap crosses zero. A body that starts on a
    // wall and stays pressed to it (resting, sliding) never makes the gap cross: it would
    // pass through the wall unseen. Between located contacts the gap is never below
    // round-off; anything deeper is that, and the reference fails with the reason.
    if (sys_.has_contacts()) {
      double scale = 1.0;
      for (const double v : y) scale = std::max(scale, std::abs(v));
      if (const double gap = sys_.contact_gap(tout, y); gap < -1e-9 * scale)
        throw std::runtime_error(std::string(source_) + ": a body went through a contact unseen by t=" +
                                 detail::num(tout) + " (gap " + detail::num(gap) +
                                 "): a body resting or sliding on a wall is a lasting contact, which root location "
                                 "cannot follow");
    }
    return y;
  }

  long contacts() const { return contacts_; }

  // The counters over every segment. Since SUNDIALS 6.2 CVodeGetNumNonlinSolvConvFails
  // counts every nonlinear solver failure, including ones recovered by a Jacobian update
  // within the same attempt; the failed step attempts are CVodeGetNumStepSolveFails
  // (SUNDIALS changelog, release 6.2.0).
  reference_stats stats() {
    reference_stats s = before_reinit_;
    add_counters(s);
    s.rhs_evals_counted = st_.calls;
    return s;
  }

 private:
  bool banded() const {
    return method_ == cvode_method::bdf && sys_.force_jacobian && sys_.coupling_bandwidth >= 0 &&
           2 * (2 * sys_.coupling_bandwidth + 1) + 1 < sys_.n;
  }
  [[noreturn]] void fail(const std::string& call, int flag, flag_namer namer = &CVodeGetReturnFlagName) const {
    throw std::runtime_error(
        st_.failure(source_, call, flag, namer ? detail::sundials_flag_name(namer(flag)) : "see SUNDIALS docs"));
  }
  void check(const char* call, int flag, flag_namer namer = &CVodeGetReturnFlagName) const {
    if (flag != 0) fail(call, flag, namer);
  }
  void check_ptr(const char* call, const void* p) const {
    if (!p) throw std::runtime_error(std::string(source_) + ": " + call + " returned null");
  }
  void add_counters(reference_stats& into) {
    long steps = 0, err_fails = 0, solve_fails = 0, rhs = 0, nni = 0, lin_rhs = 0, jac = 0;
    check("CVodeGetNumSteps", CVodeGetNumSteps(h_.mem, &steps));
    check("CVodeGetNumErrTestFails", CVodeGetNumErrTestFails(h_.mem, &err_fails));
    check("CVodeGetNumStepSolveFails", CVodeGetNumStepSolveFails(h_.mem, &solve_fails));
    check("CVodeGetNumRhsEvals", CVodeGetNumRhsEvals(h_.mem, &rhs));
    into.steps += steps;
    into.failed_steps += err_fails + solve_fails;
    into.rhs_evals += rhs;
    if (method_ == cvode_method::bdf) {
      check("CVodeGetNumNonlinSolvIters", CVodeGetNumNonlinSolvIters(h_.mem, &nni));
      check("CVodeGetNumLinRhsEvals", CVodeGetNumLinRhsEvals(h_.mem, &lin_rhs), &CVodeGetLinReturnFlagName);
      check("CVodeGetNumJacEvals", CVodeGetNumJacEvals(h_.mem, &jac), &CVodeGetLinReturnFlagName);
      into.newton_iterations += nni;
      into.lin_rhs_evals += lin_rhs;
      into.jac_evals += jac;
      into.linear_solves += nni;  // a direct linear solver does one solve per Newton iteration
    }
  }

  const ode_system& sys_;
  cvode_method method_;
  const char* source_;
  cvode_callback_state st_;
  cvode_handles h_;  // after st_: freed first, while the callbacks' state still exists
  reference_stats before_reinit_;
  long contacts_ = 0, roots_ = 0;
  std::vector<double> y_resolved_;
};

}  // namespace

reference_solution solve_cvode(const ode_system& sys, std::span<const double> times, cvode_method method,
                               reference_tolerances tol) {
  cvode_session cv(sys, method);
  return detail::timed_solve(cv.source(), sys, times, tol, [&](reference_solution& out) {
    cv.create(tol);
    cv.attach_solver();
    cv.enable_contacts();
    for (double tout : times) {
      const auto y = cv.advance(tout);
      out.y.emplace_back(y.begin(), y.end());
    }
    out.stats = cv.stats();
    out.contacts = cv.contacts();
  });
}

}  // namespace stepbench

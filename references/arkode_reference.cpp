// Solutions from SUNDIALS ARKODE 5.x's explicit Runge-Kutta stepper (ERKStep): with its
// default table of order 8 (ARKODE_FEHLBERG_13_7_8) an independent high-order reference
// beside GSL's rk8pd; as a peer (order 8, or 5: ARKODE_CASH_KARP_6_4_5 in SUNDIALS 6.4,
// arkode_erkstep.h's ERKSTEP_DEFAULT_5), adaptive or at fixed steps, what a SUNDIALS user
// gets. ERKStepSetStopTime lands exactly on each output time instead of interpolating
// past it.
// arkode_butcher.h uses FILE without including <cstdio>, so <cstdio> comes first.
// clang-format off
#include <cstdio>
// clang-format on
#include <arkode/arkode_butcher_erk.h>
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>

#include "references/detail.hpp"
#include "references/reference.hpp"

namespace stepbench {
namespace {

// -1: unrecoverable (ARKRhsFn, user guide 5.x).
int arkode_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) noexcept {
  auto& st = *static_cast<detail::callback_state*>(user_data);
  return st.evaluate(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)) ? 0 : -1;
}

struct arkode_handles {
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  void* mem = nullptr;
  arkode_handles() = default;
  arkode_handles(const arkode_handles&) = delete;
  arkode_handles& operator=(const arkode_handles&) = delete;
  ~arkode_handles() {
    if (mem) ERKStepFree(&mem);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }
};

}  // namespace

arkode_erk_table_info arkode_erk_default_table(int order) {
  // ERKStepSetOrder's choice (arkode_erkstep.h, ERKSTEP_DEFAULT_<q>) for the orders the
  // study runs, named by arkode_butcher_erk.h's ID (which table a default is changed
  // between SUNDIALS releases: the study records the one it ran).
  if (order != 5 && order != 8)
    throw std::invalid_argument("stepbench runs ARKODE ERKStep's default tables of order 5 and 8, not " +
                                std::to_string(order));
  const int id = order == 5 ? ERKSTEP_DEFAULT_5 : ERKSTEP_DEFAULT_8;
  const char* name = id == ARKODE_DORMAND_PRINCE_7_4_5 ? "ARKODE_DORMAND_PRINCE_7_4_5"
                     : id == ARKODE_CASH_KARP_6_4_5    ? "ARKODE_CASH_KARP_6_4_5"
                     : id == ARKODE_FEHLBERG_13_7_8    ? "ARKODE_FEHLBERG_13_7_8"
                     : order == 5                      ? "ERKSTEP_DEFAULT_5"
                                                       : "ERKSTEP_DEFAULT_8";
  const ARKodeButcherTable table = ARKodeButcherTable_LoadERK(static_cast<ARKODE_ERKTableID>(id));
  if (!table) throw std::runtime_error(std::string("ARKodeButcherTable_LoadERK(") + name + ") returned null");
  arkode_erk_table_info out{name, table->stages, table->q, table->p};
  ARKodeButcherTable_Free(table);
  return out;
}

reference_solution solve_arkode_erk(const ode_system& sys, std::span<const double> times, int order,
                                    reference_tolerances tol, double fixed_step) {
  const std::string source = "arkode_erk" + std::to_string(order);
  if (fixed_step < 0.0 || !std::isfinite(fixed_step))
    throw std::invalid_argument(source + ": the fixed step must be finite and >= 0 (0: adaptive)");
  return detail::timed_solve(source, sys, times, tol, [&](reference_solution& out) {
    detail::callback_state st;
    st.sys = &sys;
    arkode_handles h;
    const auto fail = [&](const std::string& call, int flag) {
      throw std::runtime_error(
          st.failure(source, call, flag, detail::sundials_flag_name(ERKStepGetReturnFlagName(flag))));
    };
    const auto check = [&](const char* call, int flag) {
      if (flag != 0) fail(call, flag);
    };
    check("SUNContext_Create", SUNContext_Create(nullptr, &h.ctx));
    h.y = N_VNew_Serial(sys.n, h.ctx);
    if (!h.y) throw std::runtime_error(source + ": N_VNew_Serial returned null");
    std::copy(sys.y0.begin(), sys.y0.end(), N_VGetArrayPointer(h.y));
    h.mem = ERKStepCreate(&arkode_rhs, 0.0, h.y, h.ctx);
    if (!h.mem) throw std::runtime_error(source + ": ERKStepCreate returned null");
    check("ERKStepSetErrHandlerFn",
          ERKStepSetErrHandlerFn(h.mem, &detail::keep_sundials_message<detail::callback_state, ARK_WARNING>, &st));
    check("ERKStepSetUserData", ERKStepSetUserData(h.mem, &st));
    check("ERKStepSetOrder", ERKStepSetOrder(h.mem, order));
    check("ERKStepSStolerances", ERKStepSStolerances(h.mem, tol.rtol, tol.atol));
    if (fixed_step > 0.0) check("ERKStepSetFixedStep", ERKStepSetFixedStep(h.mem, fixed_step));
    check("ERKStepSetMaxNumSteps", ERKStepSetMaxNumSteps(h.mem, sys.max_steps_per_output));
    // At a discontinuity an order-8 method at a tight tolerance needs many rejections in a
    // row to shrink its step; ARKODE's default of 7 gives up where GSL and CVODE do not.
    check("ERKStepSetMaxErrTestFails", ERKStepSetMaxErrTestFails(h.mem, 100));

    const auto n = static_cast<std::size_t>(sys.n);
    for (double tout : times) {
      check("ERKStepSetStopTime", ERKStepSetStopTime(h.mem, tout));
      sunrealtype t = 0.0;
      const int flag = ERKStepEvolve(h.mem, tout, h.y, &t, ARK_NORMAL);
      if (st.error) std::rethrow_exception(st.error);
      const double* y = N_VGetArrayPointer(h.y);
      const bool finite = std::all_of(y, y + n, [](double v) { return std::isfinite(v); });
      // At a fixed step nothing shrinks the step: a step beyond the stability limit grows
      // until the right-hand side or the state is not finite, which is the run diverging.
      if (fixed_step > 0.0 && (st.non_finite || !finite)) {
        out.diverged = true;
        break;
      }
      if (flag < 0) fail("ERKStepEvolve at t=" + detail::num(t) + " towards t=" + detail::num(tout), flag);
      if (!finite) throw std::runtime_error(source + ": non-finite state at t=" + detail::num(tout));
      out.y.emplace_back(y, y + n);
    }
    auto& s = out.stats;
    check("ERKStepGetNumSteps", ERKStepGetNumSteps(h.mem, &s.steps));
    check("ERKStepGetNumErrTestFails", ERKStepGetNumErrTestFails(h.mem, &s.failed_steps));
    check("ERKStepGetNumRhsEvals", ERKStepGetNumRhsEvals(h.mem, &s.rhs_evals));
    s.rhs_evals_counted = st.calls;
  });
}

}  // namespace stepbench

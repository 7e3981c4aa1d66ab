#pragma once
// ARKODE ERKStep's default tables of order 8 and 5 at our dt (ERKStepSetFixedStep), so
// that the order fit checks what the tables declare against what SUNDIALS achieves with
// them: `arkode_erk8` (ARKODE_FEHLBERG_13_7_8) and `arkode_erk5`
// (ARKODE_CASH_KARP_6_4_5 in SUNDIALS 6.4). Each run is ARKODE's whole run (set-up,
// integration, landing on every sample time with ERKStepSetStopTime), through the one
// ARKODE wrapper (references/arkode_reference.cpp).
#include <span>
#include <vector>

#include "core/drive.hpp"
#include "core/first_order.hpp"
#include "core/method.hpp"
#include "peers/library_adaptive.hpp"
#include "references/reference.hpp"

namespace stepbench::peers {

template <int Order>
struct arkode_fixed {
  static method_info info() {
    const arkode_erk_table_info table = arkode_erk_default_table(Order);
    return {.name = Order == 8 ? "arkode_erk8" : "arkode_erk5",
            .description = "ARKODE ERKStep at fixed dt (ERKStepSetFixedStep), default order-" + std::to_string(Order) +
                           " table " + table.name,
            .origin = method_origin::peer,
            .kind = method_kind::fixed_step,
            .declared_order = static_cast<double>(table.q),
            .library = "SUNDIALS ARKODE"};
  }

  template <problem P>
  static auto prepare(const P& p, double dt, double /*horizon*/, std::span<const double> times, const run_limits&) {
    return [sys = make_ode_system(p), dim = p.dim(), dt, t = std::vector<double>(times.begin(), times.end())] {
      return as_run<typename P::vec>(solve_arkode_erk(sys, t, Order, {}, dt), dim);
    };
  }
};

}  // namespace stepbench::peers

#pragma once
// Every method as a registry entry of one shape (info, applies, prepare): our integrators
// wrapped as ours_fixed / ours_adaptive, the peers as they are (core/step_adapter.hpp),
// so that every method is run and measured by the same code. Included by the problem units
// (registry/problem_unit.cpp.in) and by registry/registry.cpp; it includes no method.
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "core/method.hpp"
#include "core/type_list.hpp"

namespace stepbench::registry_detail {

// What every one of our integrators declares (its name, description, order and
// capabilities), as a registry entry of the given kind.
template <class I>
constexpr double evals_per_step_of() {
  if constexpr (requires { I::force_evals_per_step; })
    return I::force_evals_per_step;
  else
    return std::numeric_limits<double>::quiet_NaN();
}
template <class I>
method_info ours_info(method_kind kind) {
  return {.name = std::string(I::name),
          .description = std::string(I::description),
          .origin = method_origin::ours,
          .kind = kind,
          .declared_order = static_cast<double>(I::order),
          .evals_per_step = evals_per_step_of<I>(),
          .traits = I::traits,
          .library = "stepbench"};
}

template <integrator I>
struct ours_fixed {
  using integrator_type = I;
  static constexpr bool resolves_contacts = true;  // our loops do (runs_on, below)
  template <class P>
  static constexpr bool applies = method_applies<I, P>();
  static method_info info() { return ours_info<I>(method_kind::fixed_step); }
  template <problem P>
  static auto prepare(const P& p, double dt, double horizon, std::span<const double> times, const run_limits&) {
    return [p, dt, horizon, plan = plan_records(horizon, dt, times)] { return drive(p, I{}, dt, horizon, plan); };
  }
};

template <adaptive_integrator I>
struct ours_adaptive {
  static constexpr bool resolves_contacts = true;
  template <class P>
  static constexpr bool applies = method_applies<I, P>();
  static method_info info() { return ours_info<I>(method_kind::adaptive); }
  template <problem P>
  static auto prepare(const P& p, double tol, double horizon, std::span<const double> times, const run_limits& limits) {
    // The budget in steps: the work budget over the coordinates and the method's force
    // evaluations a step.
    const long max_steps = limits.adaptive_steps(p.dim(), I::force_evals_per_step);
    return [p, tol, horizon, max_steps, t = std::vector<double>(times.begin(), times.end())] {
      return drive_adaptive(p, I(tol), horizon, t, max_steps);
    };
  }
};

// The entry of a registry type: ours wrapped by kind, a peer as it is.
template <class M>
struct entry_for {
  using type = M;
};
template <integrator I>
struct entry_for<I> {
  using type = ours_fixed<I>;
};
template <adaptive_integrator I>
struct entry_for<I> {
  using type = ours_adaptive<I>;
};
template <class M>
using entry_t = typename entry_for<M>::type;

// Our loops resolve contacts (core/drive.hpp); the peers' and the baseline's do not, so
// on a problem with contacts only our methods run (a library stepping through a ground
// plane would be measured falling through it).
template <class M, class P>
inline constexpr bool runs_on = method_applies<M, P>() && (!has_contacts<P> || requires { M::resolves_contacts; });

// One info object per entry for the whole program (an inline function's static).
template <class M>
const method_info& info_of() {
  static const method_info info = M::info();
  return info;
}

}  // namespace stepbench::registry_detail

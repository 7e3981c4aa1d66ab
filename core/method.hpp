#pragma once
// What the registry says of a method, and one run of it in plain vectors: the shape
// every method (ours, a library peer, the hand-written baseline) is measured in, by the
// same code.
#include <algorithm>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/concepts.hpp"

namespace stepbench {

// Where a method comes from. A baseline is a timing floor written by hand for one
// problem, not a method a user could pick: it is shown for scale, never recommended. A
// plugin's method was compiled outside stepbench and loaded at run time (docs/plugins.md).
enum class method_origin { ours, peer, baseline, plugin };
// What its parameter is: a timestep (a dt ladder) or a tolerance (a tolerance ladder).
enum class method_kind { fixed_step, adaptive };

// The names the study file stores, indexed by the enumerators.
inline std::string_view to_string(method_origin o) {
  constexpr std::string_view names[] = {"ours", "peer", "baseline", "plugin"};
  return names[static_cast<int>(o)];
}
inline std::string_view to_string(method_kind k) { return k == method_kind::fixed_step ? "fixed_step" : "adaptive"; }
inline std::string_view param_name(method_kind k) { return k == method_kind::fixed_step ? "dt" : "tolerance"; }

// A method the study offers a user as it offers ours (the frame rates, the energy study,
// scans, the game loop): ours, and a plugin's, which the user brought to be measured the
// same way (docs/plugins.md).
inline bool offered_as_ours(method_origin o) { return o == method_origin::ours || o == method_origin::plugin; }

// Limits on one run. The work budget is counted in force evaluations times coordinates,
// so a large scene gets proportionally fewer steps; a run that would exceed it is
// recorded as skipped (with the reason), not as failed.
struct run_limits {
  double work_budget = 1L << 25;  // coordinate force evaluations per run (about 0.1 s of force work)
  long max_steps = 1L << 21;      // accepted steps of an adaptive method per run
  // The steps an adaptive method with `evals_per_step` force evaluations may take on a
  // problem of `dim` coordinates.
  long adaptive_steps(int dim, double evals_per_step) const {
    return std::max(1L, std::min(max_steps, static_cast<long>(work_budget / (dim * evals_per_step))));
  }
};

// Where a method runs: on every problem, unless it declares
// `template <problem P> static constexpr bool applies` (Odeint's peers need a state size
// known at compile time, the baselines their own two problems).
template <class M, class P>
consteval bool method_applies() {
  if constexpr (requires { M::template applies<P>; })
    return M::template applies<P>;
  else
    return true;
}

struct method_info {
  std::string name;
  std::string description;
  method_origin origin = method_origin::ours;
  method_kind kind = method_kind::fixed_step;
  double declared_order = std::numeric_limits<double>::quiet_NaN();  // NaN: the method declares none
  // Force evaluations a step (an adaptive method's: an accepted attempt's), by its
  // construction; NaN where they depend on the problem or the solve (a velocity-dependent
  // force, Newton iterations, a library's own choices). The study measures them anyway.
  double evals_per_step = std::numeric_limits<double>::quiet_NaN();
  capabilities traits{};
  std::string library;  // "stepbench", "GSL", "SUNDIALS CVODE", "Boost.Odeint"
};

// What a run did, as every loop records it and every run is reported: its work, why it
// stopped, its sample times and its contacts (core/drive.hpp's drive_result and the plain
// run_result below both hold it).
struct run_record {
  long steps = 0;           // accepted steps
  long rejected_steps = 0;  // attempts rejected by an error test or a failed solve
  work_counters work{};     // force (right-hand-side) evaluations and an implicit method's work
  bool non_finite = false;  // a NaN or Inf appeared; the run stopped there
  // Why the run stopped before the horizon: a solver error, or the work budget
  // (`skipped`); empty when it reached the horizon.
  std::string stop_reason;
  bool skipped = false;  // not run to the end because it would exceed the work budget (reason in `stop_reason`)
  // A method that steps its own particles (xpbd): the largest max_j |C_j| / L_j of them
  // over the recorded samples; NaN for a method that steps the problem's state.
  double constraint_violation = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sample_t;
  // A method that steps its own particles on a problem whose positions are observed (xpbd
  // on n_pendulum, core/constraints.hpp's has_drawn_particles): the positions and
  // velocities it draws, [X; V] in problem_instance::observed's layout, at sample_t and
  // where it stopped. Errors are measured on them; empty for every other run, whose
  // drawn positions are its state's observed ones.
  std::vector<std::vector<double>> drawn_samples;
  std::vector<double> drawn_final;
  // Contacts (a problem with contacts, run by a loop that resolves them: core/drive.hpp).
  long contacts = 0;                  // contacts resolved (responses applied)
  long tunnelled = 0;                 // contacts found deeper than the problem's tunnelling depth
  double max_penetration = 0.0;       // the deepest penetration found before a resolution
  std::vector<double> contact_times;  // the first 64: when resolved (end_of_step: the step's end)
};

// One run of one method at one parameter, to the horizon, with the state recorded at
// the requested times, in plain vectors.
struct run_result : run_record {
  double param = 0.0;  // dt [s] or relative tolerance
  double horizon = 0.0;
  std::vector<std::vector<double>> sample_y;           // [x; v] at sample_t
  std::vector<double> final_y;                         // [x; v] where the run stopped
  std::vector<std::vector<double>> contact_positions;  // position just after each contact time (small states only)
};

}  // namespace stepbench

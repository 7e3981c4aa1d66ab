#pragma once
// The game-loop study's answers: the cost verdict of a configuration, and the cheapest
// design that keeps the shown error under the target.
#include <string>
#include <string_view>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// The cost verdict of a configuration at a step cost.
struct loop_cost {
  double step_cost_ns = 0.0;
  std::string source;  // "measured" or "stated"
  loop_schedule schedule;
  loop_outcome without_clamp = loop_outcome::keeps_up;  // the same configuration, clamp off
  bool clamp_prevented_spiral = false;                  // with the clamp no spiral, without it one
};
loop_cost cost_verdict(const loop_config& config, double step_cost_ns, std::string source);

// The benchmark's median ns per step of `method` on the problem (its timed rows that
// completed); NaN when the study has no timing for it.
double measured_step_cost_ns(const problem_study& ps, std::string_view method);
// The same per force evaluation: a scan's ranking cost (judge/scan.hpp measured_eval_costs).
double measured_eval_cost_ns(const problem_study& ps, std::string_view method);

// The cheapest design at a constant display rate whose shown error stays at or under
// the target: fewest physics steps per frame, then the smaller error, then the designs
// that do not depend on the frame rate first (fixed, interpolated, substeps, variable).
struct loop_cheapest {
  double display_hz = 0.0;
  double target = 0.0;
  bool found = false;
  std::string design;
  double physics_hz = 0.0;  // NaN for variable
  double steps_per_frame_mean = 0.0;
  double shown_err_max = 0.0;
};
std::vector<loop_cheapest> cheapest_designs(const loop_method& m, const loop_options& opts);

}  // namespace stepbench

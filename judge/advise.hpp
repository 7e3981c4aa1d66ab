#pragma once
// `stepbench advise`: answers "which method, at which dt (or tolerance), for this
// error?" from a study file (docs/study-format.md), without running anything, by the
// cheapest-method rule of core/work_precision.hpp (the same rule as the study file's
// equal-error table and `stepbench ratios`). A method that diverged at a coarser dt
// than its chosen row is still a candidate (it is stable at the chosen dt); the largest
// dt at which it diverged is reported as its stability margin. The hand-written
// baseline is shown for scale, marked as such, and is never the answer.
//
// Exit codes of the subcommand: 0 an answer; 1 the study file is missing or
// unreadable; 2 bad usage (unknown problem or metric, tol not a positive finite
// number); 3 no method in the file meets the tolerance (the best achieved is printed).
#include <string>
#include <vector>

#include "core/work_precision.hpp"
#include "study/study.hpp"

namespace stepbench {

inline constexpr int advise_exit_no_method = 3;

struct advice {
  std::string problem, metric, unit;
  std::string scene;  // the problem's parameters as the study ran it (judge/scan.hpp scene_text)
  double tol = 0.0;
  bool timed = false;
  std::vector<wp_method> methods;
  cheapest_result result;
  bool met() const { return result.answer(methods).has_value(); }
};

// Throws std::invalid_argument for an unknown metric or a problem the file lacks
// (naming the problems it has), or a tol that is not a positive finite number.
advice advise(const study& study, const std::string& problem, const std::string& metric, double tol);

struct frame_advice {
  std::string problem, unit, cost_kind;  // cost_kind: time_ns or force_evals (per frame)
  std::string scene;                     // as in advice
  double hz = 0.0, tol = 0.0, horizon = 0.0;
  std::vector<frame_option> one_step;    // every method at one step a frame
  std::vector<frame_option> ranked;      // each method's cheapest substep count meeting tol, cheapest first
  std::vector<std::string> not_meeting;  // "rk4: best 3e-5 m at x64"
  bool met() const { return !ranked.empty(); }
};

// `stepbench advise --hz`: the game programmer's question, from the study's frame-rate
// runs of one problem (study/verdict.hpp): at a frame rate, which of our fixed-step
// methods are stable at one step a frame and their error, and the cheapest method and
// substep count a frame whose err_pos_max is at or under `tol`. Throws
// std::invalid_argument for a rate the runs lack (naming what they have) or a bad tol.
frame_advice advise_frame(const study& s, const std::string& problem, double hz, double tol);

// Why `s` cannot answer advise_frame for this problem and rate ("" when it can): it has no
// frame-rate runs of the problem, or not at that rate (naming those it has).
std::string frame_runs_missing(const study& s, const std::string& problem, double hz);

}  // namespace stepbench

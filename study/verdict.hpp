#pragma once
// The answer a user comes for, computed once when the study is written and stored in it
// (/verdict, docs/study-format.md); the report's first screen, `stepbench advise --hz`,
// `stepbench ratios` and the end of a study run all show these tables, never a second
// computation.
//
//  - Equal error: for each problem and error target (err_pos_max, 1e-2 .. 1e-12 in the
//    problem's unit), the fastest of our methods and the fastest library peer by the cost
//    at equal error interpolated on each method's measured work-precision curve
//    (core/work_precision.hpp), their ratio, and whether the ratio lies outside the
//    repetition spread ("ahead" / "behind") or within it.
//  - Frame rates, the game programmer's question: at 30, 60, 120 and 240 Hz, every fixed-step
//    method of ours is run at n = 1, 2, 4, ..., 64 substeps a frame over the whole frames of
//    the problem's horizon and measured against the truth at the frame ends. Which methods
//    are stable at one step a frame and their error; for each target the cheapest method
//    and substep count that meets it. The cost of a frame is the benchmark's median ns per
//    step of the method on the problem times the steps of a frame (timed study), else the
//    force evaluations of a frame.
//  - Findings: a few sentences generated from these and the other studies' verdicts.
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "study/substeps.hpp"

namespace stepbench {

struct cost_at_error {
  std::string method, kind;  // empty method: none reaches the target
  double param = 0.0, cost = 0.0, cost_lo = 0.0, cost_hi = 0.0;
  bool interpolated = false;  // false: an upper bound (a measured row under the target)
  // Force evaluations at equal error, interpolated the same way (a bound's own row's): a
  // time ratio is this ratio times the ratio of time an evaluation (the step's overhead
  // included). NaN when none reaches the target, and for a plugin (not stored).
  double force_evals = std::numeric_limits<double>::quiet_NaN();
  bool found() const { return !method.empty(); }
};

struct equal_error_verdict {
  std::string problem, unit;
  double target = 0.0;
  cost_at_error ours, peer;
  double ratio = 0.0;     // ours / peer; NaN unless both
  std::string cost_kind;  // time_ns or force_evals: what ranked this target (core/work_precision.hpp)
  // "ahead", "behind", "within spread" (the timing noise), "bounded" (the side that would
  // lose is charged an upper bound: its ladder does not bracket the target, so the
  // comparison cannot be decided), "ours only", "peers only", "not reached".
  std::string verdict;
  double best_error = 0.0;
  // The noise the ratio was judged against, as a factor b = 1 + core/work_precision.hpp's
  // threshold: "ahead" or "behind" only outside [1 / b, b]; the timing noise by measured
  // time (b >= 1.15), 1 + 1e-9 (rounding) by counted force evaluations. NaN unless both found.
  double noise_factor = std::numeric_limits<double>::quiet_NaN();
  // Why the ratio is what it is: ratio = evals_ratio x per_eval_ratio, ours / peer in force
  // evaluations at equal error, and in time an evaluation (the force plus the step's own
  // work). evals_ratio NaN unless both found; per_eval_ratio also NaN when this target was
  // ranked by force evaluations (cost_kind), where the ratio is evals_ratio itself.
  double evals_ratio = std::numeric_limits<double>::quiet_NaN();
  double per_eval_ratio = std::numeric_limits<double>::quiet_NaN();
};

// A plugin's answer to "how does my method compare?": for each problem and target, the
// fastest plugin method at equal error against the fastest of ours and the fastest
// library peer (each as equal_error_verdict ranks them), with the same rule and noise band.
// Present only in a study that loaded plugins (--plugin).
struct plugin_at_error {
  std::string problem, unit;
  double target = 0.0;
  cost_at_error plugin;
  double vs_ours = std::numeric_limits<double>::quiet_NaN();  // plugin / ours; NaN unless both found
  double vs_peer = std::numeric_limits<double>::quiet_NaN();  // plugin / peer; likewise
  std::string cost_kind;                                      // as equal_error_verdict's at the same (problem, target)
  // As equal_error_verdict's verdict, from the plugin's side: "ahead" = the plugin's cheaper;
  // "plugin only" where the other side reaches no target, "others only", "not reached".
  std::string verdict_ours, verdict_peer;
};

struct frame_stability {
  std::string problem, unit, method, note;
  double hz = 0.0;
  bool stable = false;
  double err_pos_max = 0.0;
};

struct frame_answer {
  std::string problem, unit, method;  // empty: none within the largest substep count
  double hz = 0.0, target = 0.0;
  int substeps = 0;
  double err_pos_max = 0.0, cost_per_frame = 0.0, frame_share = 0.0;
};

struct verdict_tables {
  std::string cost_kind;  // "time_ns" or "force_evals"
  std::vector<equal_error_verdict> equal_error;
  std::vector<plugin_at_error> plugin_equal_error;
  std::vector<frame_stability> frame_rate;
  std::vector<frame_answer> frame_answers;
  std::vector<std::string> findings;
};

// What the findings are generated from besides the verdict tables, as a study holds it
// and as its file does: `stepbench merge` generates a merged study's findings from the
// merged file by the same code.
struct substep_finding {
  std::string problem;
  double frame_dt = 0.0;
  substep_verdict verdict;  // implicit_euler against semi_implicit_euler
};
// xpbd's runs over a problem's dt ladder (coarse to fine, as the study stores them): what
// the finding on its stability and energy reads.
struct ladder_run {
  double dt = 0.0;
  bool diverged = false, failed = false, skipped = false;
  double energy_drift = 0.0, constraint_violation = 0.0;
};
struct ladder_finding {
  std::string method;  // a method with capabilities::small_steps (xpbd)
  std::string problem;
  std::vector<ladder_run> runs;
};
struct finding_inputs {
  std::vector<substep_finding> substeps;                       // in the study's problem order
  std::map<std::string, std::set<std::string>> broken_orders;  // peer -> problems where its declared order fails
  std::vector<ladder_finding> small_steps_ladders;             // in the study's problem order
};
// Two studies' equal-error verdicts side by side (`stepbench compare`): over the
// (problem, target) pairs where both say "ahead" or "behind", how many agree and which
// flip; and how many are decided in one and within the spread in the other. Of the same
// code, a flip means the spread understates the noise; between versions, a change.
struct verdict_agreement {
  int both_decided = 0, agree = 0, decided_in_one = 0;
  std::vector<std::string> flips;  // "pendulum at 1e-06: ahead (0.94x) -> behind (1.03x)"
};
// One frame-rate run as /frame_rates/<problem>/runs holds it, with its cost a frame.
struct frame_option {
  std::string method, note;
  double hz = 0.0;
  int substeps = 1;
  double dt = 0.0;
  bool completed = false, diverged = false;
  double err_pos_max = 0.0;  // NaN unless completed
  long steps = 0;
  double force_evals = 0.0, cost_per_frame = 0.0;
};

}  // namespace stepbench

#pragma once
// A scene's whole range (issue 20): `stepbench scan` runs the fixed-step methods over a
// grid of a problem's declared parameters and, at each grid point, over frame rates and
// substeps, as the frame-rate study does at the default point (study/verdict.hpp): whole
// frames of the slowest rate against the truth at the frame ends (the closed form, else
// the references, which may fail at a point: recorded there, the scan goes on).
//
// Per grid point, rate, method and substep count: completed or diverged (or failed),
// err_pos_max, the counted cost (force evaluations, Newton iterations); per grid point
// and rate, the cheapest method and substep count whose error meets the tolerance. The
// answer to "which method is cheapest, stays stable and within my tolerance over my
// whole range, and where does each break" is read from these (`advise --scan`).
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/method.hpp"
#include "references/reference.hpp"
#include "study/method_row.hpp"

namespace stepbench {

// One axis of the grid: `problem.param=lo:hi:count[:log]`.
struct scan_axis {
  std::string param;
  double lo = 0.0, hi = 0.0;
  int count = 1;
  bool log = false;
  bool whole = false;                  // the parameter takes whole numbers: values are rounded
  std::vector<double> values() const;  // lo .. hi, count points, evenly (in log when `log`)
};

// The frame-rate study (study/verdict.hpp): our fixed-step methods at whole frames of
// each rate, with n substeps a frame; a scan runs it at each grid point.
struct frame_rate_options {
  std::vector<double> hz{30, 60, 120, 240};  // each divides the largest, so one truth serves all
  std::vector<int> substeps{1, 2, 4, 8, 16, 32, 64};
};

// scan_options::cost_source of costs timed on the scene itself (`advise --hz H --time`).
inline constexpr std::string_view cost_timed_here = "timed here on this scene (advise --time)";

struct scan_options : frame_rate_options {  // its rates and substeps (`scan --dt X` is hz 1/X)
  std::string problem;
  std::string name;  // the group under /scan ("" : the problem's name)
  std::vector<scan_axis> axes;
  // Empty: our fixed-step methods on the problem. A scan's result holds those it ran.
  std::vector<std::string> methods;
  double tol = 1e-3;                    // in the problem's position unit
  std::map<std::string, double> fixed;  // other parameters of the problem (--set)
  // The ranking's cost (scan_cost): each method's ns per force evaluation measured on this
  // problem by a timed study's benchmark (`scan --costs FILE`, the study `advise` reads),
  // so a scan and `advise --hz` rank one scene alike: a frame's cost is its evaluations x
  // its method's. Empty: the evaluations alone. `cost_source` names where they come from.
  std::map<std::string, double> ns_per_force_eval;
  std::string cost_source;  // the timed study's path, or cost_timed_here
  reference_tolerances ref_tol{};
  // At a point whose references' predicted work (core/measure.hpp predicted_reference_work:
  // coordinates x w_max T) is over this, the references are not run: the point has no
  // trusted truth, says why, and its runs are judged on stability alone (diverged or
  // not); no error, so no tolerance answer there. The default keeps a point's references
  // to seconds on one core (spring_chain at 512 masses and k_s 100 N/m is 4e5, at 4096
  // masses and 1e5 N/m 5e8: hours). Infinity: every point's references.
  double reference_budget = 2e6;
  // A run whose work (steps x force evaluations a step x coordinates) would exceed
  // limits.work_budget is recorded as skipped, not run.
  run_limits limits{};
  int jobs = 0;  // threads over the grid points (0: one a core)
  // --shard K/N: this run takes shard `shard_index` (0-based) of `shard_count`, a
  // deterministic share of the grid points balanced by their counted size (scan_shard).
  int shard_index = 0, shard_count = 1;
  // Progress: called after each grid point with the points done and the total.
  std::function<void(std::size_t done, std::size_t total)> on_progress;
};

struct scan_run {
  std::size_t point = 0;  // index into scan_result::points (not the grid: see scan_point::index)
  double hz = 0.0;
  std::string method;
  int substeps = 1;
  method_row row;  // param is dt
};

struct scan_point {
  std::size_t index = 0;       // the point's place in the whole grid (scan_grid), across shards
  std::vector<double> values;  // one per axis
  std::string truth_source;    // closed_form, a reference, or none
  bool trusted = true;
  std::string note;        // why the truth is not trusted, or why the point was not run
  double horizon = 0.0;    // whole frames of the slowest rate
  double pos_scale = 1.0;  // the motion's amplitude
};

// The cost by which a scan ranks `force_evals` force evaluations of `method`: their time in
// ns at the options' measured ns per evaluation, else the count itself; NaN for a method
// the measured costs lack (it is not ranked).
double scan_cost(const scan_options& o, const std::string& method, double force_evals);

// The cheapest run at a point and rate that completed with err_pos_max <= tol, by scan_cost
// (ties to the fewer substeps, then the registry order).
struct scan_best {
  std::size_t point = 0;
  double hz = 0.0;
  std::string method;  // "" when none meets the tolerance
  int substeps = 0;
  double err_pos_max = 0.0;
  double force_evals_per_frame = 0.0;
};

struct scan_result {
  scan_options options;
  std::string unit;  // the problem's position unit
  // The range answer at the scan's tolerance, as `scan` and `advise --scan` print it:
  // judged once (parts/scans.cpp), so the report and the README quote it, not redo it.
  std::string range_answer;
  std::size_t grid_points = 0;     // the whole grid's points; `points` holds them all unless sharded
  std::vector<scan_point> points;  // in grid order
  std::vector<scan_run> runs;
  std::vector<scan_best> best;
  double wall_seconds = 0.0;  // a merged scan's: the sum of its shards'
  std::string source;         // the file it was read from ("" when run here): merge names it
};

// The range question answered from a scan at a tolerance (which may differ from the
// scan's own): at each rate, the cheapest method and substep count that completes within
// `tol` at every trusted grid point (cost: its largest force evaluations a frame over the
// points), and where each method breaks at one step a frame.
struct scan_choice {
  double hz = 0.0;
  std::string method;  // "" when no method and substep count holds over the whole range
  int substeps = 0;
  double worst_err = 0.0;
  double max_force_evals_per_frame = 0.0;
  double max_cost_per_frame = 0.0;  // by scan_cost: ns, or force evaluations (scan_answer::cost_kind)
};

struct scan_break {
  double hz = 0.0;
  std::string method;
  std::size_t unstable = 0;  // points where one step a frame diverged or failed
  std::size_t points = 0;    // trusted points run
  std::string where;         // "diverges for k_s >= 3.16e4 N/m" (one axis), or the first point
};

struct scan_answer {
  std::string problem, unit, range;                    // range: "over k_s 10 .. 1e7 (25 points, log)"
  std::string cost_kind = "force_evals", cost_source;  // cost_kind: time_ns with measured costs
  std::map<std::string, double> ns_per_force_eval;
  std::vector<std::string> uncosted;  // methods run that the measured costs lack: not ranked
  double tol = 0.0;
  std::size_t points = 0, grid_points = 0, untrusted = 0;
  std::vector<scan_choice> choices;
  std::vector<scan_break> breaks;
};

// The cheapest run meeting the tolerance at each point and rate (scan_result::best), from
// its runs: after a scan's run, its read and its merge.
void compute_best(scan_result& s);

}  // namespace stepbench

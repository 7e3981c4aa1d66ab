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

// Parses `P.name=lo:hi:count[:log]` for problem P; throws std::invalid_argument with a
// one-line reason (another problem, an unknown parameter, a bound outside the parameter's
// declared range, count < 1 or above 10^5, log with a bound <= 0).
scan_axis parse_scan_axis(std::string_view text, const std::string& problem);

struct scan_options {
  std::string problem;
  std::string name;  // the group under /scan ("" : the problem's name)
  std::vector<scan_axis> axes;
  std::vector<double> hz{30, 60, 120, 240};  // each divides the fastest (--dt X is hz 1/X)
  std::vector<int> substeps{1, 2, 4, 8, 16, 32, 64};
  // Empty: our fixed-step methods on the problem. A scan's result holds those it ran.
  std::vector<std::string> methods;
  double tol = 1e-3;                    // in the problem's position unit
  std::map<std::string, double> fixed;  // other parameters of the problem (--set)
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

// Checks the options; throws std::invalid_argument with a one-line reason.
void validate(const scan_options& opts);

// The scans of the full study: stiff_spring over k_s 1e1 .. 1e7 N/m (25 points, log), the
// pendulum over its release angle 1 .. 179.9 deg (12 points) and spring_chain over 8 .. 4096
// masses x k_s 1e2 .. 1e5 N/m (4 x 4, log), each at 30 .. 240 Hz with 1 .. 64 substeps;
// `quick`: the stiff spring's 13 points at 60 Hz only (the CI study).
std::vector<scan_options> default_scans(bool quick = false);

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

// The cheapest run at a point and rate that completed with err_pos_max <= tol, by force
// evaluations (our methods' counted cost; ties to the fewer substeps, then the registry order).
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
  std::string unit;                // the problem's position unit
  std::size_t grid_points = 0;     // the whole grid's points; `points` holds them all unless sharded
  std::vector<scan_point> points;  // in grid order
  std::vector<scan_run> runs;
  std::vector<scan_best> best;
  double wall_seconds = 0.0;  // a merged scan's: the sum of its shards'
  std::string source;         // the file it was read from ("" when run here): merge names it
};

scan_result run_scan(const scan_options& opts);

// The grid points in order: the first axis varies slowest.
std::vector<std::vector<double>> scan_grid(const std::vector<scan_axis>& axes);

// The grid points of shard k of n (0-based), in grid order: each point's size is counted
// as its problem's coordinates (the force work of a step grows with them), and the points,
// largest first (ties in grid order), go each to the shard with the least so far (ties to
// the lowest shard). Deterministic: every machine computes the same split.
std::vector<std::size_t> scan_shard(const scan_options& opts, int k, int n);

// Joins shards of one scan (the same problem, axes, rates, substeps, methods, tolerance,
// fixed parameters, reference tolerances and work budget) into one scan, points in grid
// order; throws std::invalid_argument naming the first difference and the two values, a
// point two shards hold, or, unless `partial`, the points none holds. `missing` receives
// the grid indices no shard holds. A shard may hold no point (N above the grid's points).
scan_result merge_scans(const std::vector<scan_result>& shards, bool partial, std::vector<std::size_t>& missing);

}  // namespace stepbench

namespace stepbench {

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
};

struct scan_break {
  double hz = 0.0;
  std::string method;
  std::size_t unstable = 0;  // points where one step a frame diverged or failed
  std::size_t points = 0;    // trusted points run
  std::string where;         // "diverges for k_s >= 3.16e4 N/m" (one axis), or the first point
};

struct scan_answer {
  std::string problem, unit, range;  // range: "k_s 10 .. 1e7 (25 points, log)"
  double tol = 0.0;
  std::size_t points = 0, grid_points = 0, untrusted = 0;
  std::vector<scan_choice> choices;
  std::vector<scan_break> breaks;
};

scan_answer answer_scan(const scan_result& scan, double tol);
std::string format_scan_answer(const scan_answer& a);

// Reads /scan/<name> of a study file (name "" : the only scan in it); throws
// std::runtime_error naming the file and what is wrong, std::invalid_argument for a
// name it does not hold (listing those it does).
scan_result read_scan(const std::string& path, const std::string& name);

// Every scan of a study file, and the build that wrote it (format_version, git_commit,
// build_type, build_flags as one line), for `stepbench merge`; errors as read_scan's.
std::vector<scan_result> read_scans(const std::string& path);
std::string file_build(const std::string& path);

}  // namespace stepbench

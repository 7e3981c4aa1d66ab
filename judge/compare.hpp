#pragma once
// `stepbench compare BASE NEW`: did anything get worse between two study files?
//
// Accuracy is deterministic, so it gates: every figure of a (problem, method, row) in both
// files goes through a decision function (an error growing, a row newly diverging or
// failing, an observed order dropping, a reference or the truth getting worse); each
// finding is a regression or an improvement. Timing is noisy, so it informs: a row's time
// ratio is flagged only beyond a noise threshold from both files' repetitions, and gates
// only when asked (`gate_timing`). The checks are one function per group of the study
// file, called from one list in compare.cpp; render/compare_render.cpp draws the result.
//
// Exit status of the command: 0 nothing regressed, 1 a regression (or, with
// gate_timing, a flagged slowdown), 2 could not compare (bad usage, a file read_study
// refuses, or two files of different format versions).
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

inline constexpr int compare_exit_regression = 1;
inline constexpr int compare_exit_cannot_compare = 2;

// Round-off floors. Below them a grown error is not a regression (nor a shrunk one an
// improvement): a change in the order of operations (another compiler, FMA contraction)
// moves errors at round-off by factors, not by rounding. 1e-12 relative lies above the
// round-off plateau of the finest ladder rows (about 1e-15 for the exact methods, 1e-13
// for the high-order ones) and below every truncation error the default ladders measure.
inline constexpr double error_floor_rel = 1e-12;  // x pos_scale (position errors), x vel_scale (velocity)
// A reference's agreement (err_pos_rel, err_vel_rel) is already relative; the reference
// tolerance is 1e-13, so agreement below it is noise.
inline constexpr double agreement_floor = 1e-13;
// A stability limit (/stability/limits, theory) that moves by more than this regresses.
inline constexpr double stability_tolerance = 0.01;

// Timing noise (timing_noise_floor and the rest): core/work_precision.hpp, shared with the equal-error verdict.

struct compare_options {
  double error_factor = 2.0;  // an error or a reference's agreement growing by more than this regresses
  double order_drop = 0.1;    // an observed order moving by more than this
  // What only one side has (a problem, a method, a reference, rows of a ladder) is listed,
  // not a regression: the comparison is of what both hold. With require_base, what only
  // BASE has regresses (a gate comparing a study with one of the same design).
  bool require_base = false;
  bool gate_timing = false;  // a flagged slowdown is a regression
};

// The thresholds in force, one sentence a line (for --help and every output).
std::vector<std::string> describe_thresholds(const compare_options& opts);

// An old or new value: a number, or a status ("ok", "fitted", "closed_form").
using compare_value = std::variant<double, std::string>;

enum class change_kind { regression, improvement };

// One finding. `method` is empty for the problem itself (truth, a reference), `param_name`
// ("dt", "tolerance") empty unless the finding is about one row.
struct change {
  change_kind kind = change_kind::regression;
  std::string problem, method, param_name;
  double param = std::numeric_limits<double>::quiet_NaN();
  std::string what;  // "err_pos_max", "diverged", "observed order", "reference cvode_bdf status", ...
  compare_value old_value, new_value;
  double ratio = std::numeric_limits<double>::quiet_NaN();  // new / old where that means something
  std::string note;                                         // the new row's note, a reference's reason
};

// Something only one file has: a problem, a method, a reference, or rows of a ladder.
struct presence {
  std::string problem, method;
  std::string what;    // "problem", "method", "reference <source>", "ladder"
  std::string detail;  // e.g. "dt 0.000976562 s, dt 0.000488281 s (2 of 10 rows)"
};

// A setting that differs between the files: a root attribute (cpu, compiler, git_commit,
// levels, ...) or a problem's parameter ("pendulum: theta0_deg").
struct difference {
  std::string what;
  std::string old_value, new_value;
};

// A row's (time_ns_max - time_ns_min) / time_ns; NaN with fewer than two repetitions (no
// spread to measure).
double spread(const timing& t);
// One row timed in both files.
struct timing_row {
  std::string problem, method, param_name;
  double param = 0.0;
  timing old_time, new_time;
  double ratio = 0.0;      // new median / old median
  double threshold = 0.0;  // timing_threshold(old, new)
  int flag = 0;            // +1 slower beyond the threshold, -1 faster, 0 within the noise
};
// Per method, over every problem: the geometric mean of its rows' ratios.
struct timing_summary {
  std::string method;
  std::size_t problems = 0, rows = 0, slower = 0, faster = 0;
  double geomean = 0.0, min_ratio = 0.0, max_ratio = 0.0;
};

struct comparison {
  compare_options options;
  std::string base_path, new_path;
  std::map<std::string, std::string> base_meta, new_meta;  // as read (created_utc, git_commit, ...)
  std::vector<difference> differences;
  std::vector<change> changes;  // regressions and improvements, in file order
  std::vector<presence> added, removed;
  bool base_timed = false, new_timed = false;
  // Timing: compared only when both files are timed; otherwise `timing_note` says why
  // not. When compared, it notes a machine or build difference the ratios include.
  bool timing_compared = false;
  std::string timing_note;
  std::vector<timing_row> timing;  // every row timed in both
  std::vector<timing_summary> timing_summaries;

  std::size_t count(change_kind k) const;
  std::size_t slower() const;  // flagged slowdowns
  std::size_t faster() const;
  // Regressions, counting what was removed (with require_base) and flagged
  // slowdowns (with gate_timing).
  std::size_t gating() const;
  int exit_status() const { return gating() > 0 ? compare_exit_regression : 0; }
};

// Compares two studies read by read_study. Throws std::runtime_error when they cannot be
// compared (different format versions), std::invalid_argument for bad options.
comparison compare_studies(const study& base, const study& next, const compare_options& opts = {});

// The decision functions, one per kind of figure (exposed for the tests): an error of a row
// completed in both files (floor: the round-off floor in its unit), a reference's relative
// agreement, an observed order (fit_slope of a fixed-step method, both fitted).
std::optional<change_kind> judge_error(double old_err, double new_err, double floor, double factor);
std::optional<change_kind> judge_agreement(double old_rel, double new_rel, double factor);
std::optional<change_kind> judge_order(double old_order, double new_order, double drop);
// The noise threshold of a row timed in both files, and its flag (+1, -1, 0).
double timing_threshold(const timing& old_time, const timing& new_time);
int judge_timing(double ratio, double threshold);

}  // namespace stepbench

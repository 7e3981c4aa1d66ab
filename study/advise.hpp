#pragma once
// `stepbench advise`: answers "which method, at which dt, for this error?" from a study
// file (docs/study-format.md), without running anything.
//
// Candidates are every row of every integrator (/<problem>/<integrator>/convergence) and
// every peer (/<problem>/<peer>/work_precision) of the problem. A row qualifies when it
// did not diverge, its metric is <= tol, and (in a timed study) its timing was not cut
// by the time budget. Each method is represented by its cheapest qualifying row; the
// methods are ranked by that cost (ties: lower error, then name). The cost is the measured time (time_ns) when every
// qualifying row has one, else the counted force evaluations; the result says which.
// A method that diverged at a coarser dt than its chosen row is still a candidate (it
// is stable at the chosen dt); the largest dt at which it diverged is reported as its
// stability margin.
//
// Exit codes of the subcommand: 0 an answer; 1 the study file is missing or
// unreadable; 2 bad usage (unknown problem or metric, tol not a positive finite
// number); 3 no method in the file meets the tolerance (the best achieved is printed).
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace stepbench {

inline constexpr int advise_exit_no_method = 3;

// The metrics a user may ask for (fields of `convergence`; peers record only the
// first two, so a peer is excluded for the others).
inline constexpr const char* advise_metrics[] = {"err_pos_max", "err_pos_final", "err_pos_rms", "err_vel_final"};

struct advise_row {
  double param = 0.0;  // dt [s], or the relative tolerance of an adaptive peer
  std::int64_t force_evals = 0;
  double time_ns = std::numeric_limits<double>::quiet_NaN();  // NaN: not timed
  bool cut = false;                                           // timing skipped by the budget
  bool diverged = false;
  double error = std::numeric_limits<double>::quiet_NaN();  // the chosen metric
};

struct advise_method {
  std::string name;
  bool peer = false;
  bool adaptive = false;    // param is a tolerance, not a dt
  bool has_metric = true;   // false: this peer does not record the chosen metric
  std::vector<advise_row> rows;
};

struct advise_input {
  std::string problem;
  std::string metric = "err_pos_max";
  std::string unit = "m";  // the problem's position unit (velocity metric: unit/s)
  bool timings = false;    // the study carries time_ns / cut
  std::vector<advise_method> methods;
};

struct advise_pick {
  std::string method;
  bool peer = false;
  bool adaptive = false;
  advise_row row;
  double cost = 0.0;
  // The params (dt, or tolerance) at which this method diverged: the largest, the
  // smallest (the edge of stability seen in the study) and how many; nullopt if never.
  std::optional<double> largest_diverged, smallest_diverged;
  int diverged_rows = 0;
};

struct advise_exclusion {
  std::string method;
  std::string reason;  // "diverged ...", "too inaccurate: ...", "too slow: ...", "no ... recorded"
};

struct advise_result {
  std::string problem, metric, unit;
  double tol = 0.0;
  bool timings = false;
  std::string cost;  // "time_ns" or "force_evals"
  std::vector<advise_pick> ranked;  // best first; empty when no method meets tol
  std::vector<advise_exclusion> excluded;
  std::optional<advise_pick> best_achieved;  // when ranked is empty: lowest error in the file
};

// Reads the candidates of `problem` from the study file. Throws std::runtime_error when
// the file is missing or not a readable study file, std::invalid_argument for an
// unknown metric or a problem the file lacks (naming the problems it has).
advise_input read_advise_input(const std::string& study_path, const std::string& problem,
                               const std::string& metric = "err_pos_max");

// The decision itself, on data already read (tested without a file). tol > 0.
advise_result advise(const advise_input& in, double tol);

// The human-readable answer (several lines, ends with a newline).
std::string format_advice(const advise_result& r, std::size_t runners_up = 5);

// "dt 0.0390625 s" or "rtol 1e-08".
std::string format_param(const advise_pick& p);

}  // namespace stepbench

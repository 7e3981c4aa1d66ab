#pragma once
// The figures derived from the rows of a study: "the cheapest method that reaches an
// error" and the work-precision (Pareto) front. One rule each, used by everything that
// shows them: `stepbench advise`, the study file's equal-error and front tables (which
// the report draws and the README's tables come from) and `stepbench ratios`.
//
// The cheapest-method rule. A row qualifies for a target error when the run completed
// (did not diverge or fail), its error is at or below the target, and, in a timed study,
// its timing was not cut by the time budget. Each method is represented by its cheapest
// qualifying row (on a tie, the more accurate one). The cost is the measured time (the
// median wall time of one whole run) when every qualifying row of every method has one,
// else the counted force evaluations. Methods are ranked by that cost, then by error,
// then by name. Only measured rows count: no interpolation between ladder rows, so
// every answer is a dt (or tolerance) that was run and a cost that was measured. The
// hand-written baseline is ranked for scale but is never the answer.
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/method.hpp"

namespace stepbench {

// The error metrics a user may rank by (fields of a study's rows).
inline constexpr const char* error_metrics[] = {"err_pos_max", "err_pos_final", "err_pos_rms", "err_vel_final"};
bool is_error_metric(std::string_view name);

struct wp_row {
  double param = 0.0;                                         // dt [s] or relative tolerance
  double error = std::numeric_limits<double>::quiet_NaN();    // the chosen metric
  double time_ns = std::numeric_limits<double>::quiet_NaN();  // NaN: not timed
  double force_evals = 0.0;
  bool completed = true;  // did not diverge or fail
  bool diverged = false;
  bool cut = false;  // timing skipped by the time budget
};

struct wp_method {
  std::string name;
  method_origin origin = method_origin::ours;
  method_kind kind = method_kind::fixed_step;
  std::vector<wp_row> rows;
};

struct wp_pick {
  std::size_t method = 0;  // index into the input
  std::size_t row = 0;     // index into that method's rows
  double cost = 0.0;
  // The params at which this method diverged: the largest and smallest (the edge of
  // stability seen in the study) and how many rows; nullopt if never.
  std::optional<double> largest_diverged, smallest_diverged;
  int diverged_rows = 0;
};

struct wp_exclusion {
  std::size_t method = 0;
  std::string reason;  // "diverged at every dt", "too inaccurate: ...", "too slow: cut by the time budget ..."
};

struct cheapest_result {
  double target = 0.0;
  std::string cost;             // "time_ns" or "force_evals"
  std::vector<wp_pick> ranked;  // cheapest first, baselines included (flagged by origin)
  std::vector<wp_exclusion> excluded;
  std::optional<wp_pick> best_achieved;  // when no method of ours or a peer qualifies: lowest error seen
  // The answer: the first ranked method that is not a baseline; nullopt when none.
  std::optional<wp_pick> answer(const std::vector<wp_method>& methods) const;
};

// Which methods compete. The two callers genuinely differ:
//  - every_method: advise and the study file's equal-error table rank every method; one
//    the benchmark did not time still has its force evaluations, and the cost falls back
//    to them (the rule above) rather than leaving the method out of the answer;
//  - timed_methods: `stepbench ratios` quotes times, so it leaves out a method with no
//    timed row at all (one a --benchmark_filter left out of the timed run), which would
//    otherwise turn every cost at the target into force evaluations. Such a method is
//    neither ranked nor excluded.
enum class wp_candidates { every_method, timed_methods };

// The rule above. `timed`: the study carries timings (cut rows are then excluded).
// `unit` is used only in the exclusion reasons. Indices in the result are into
// `methods`. Throws std::invalid_argument unless target > 0 and finite.
cheapest_result cheapest(const std::vector<wp_method>& methods, double target, bool timed, const std::string& metric,
                         const std::string& unit, wp_candidates candidates = wp_candidates::every_method);

// The Pareto front of every usable row of every method, by cost (time_ns, or
// force_evals when `by_time` is false) against error: going up in cost, a row joins
// the front only if its error is lower than every cheaper row's by more than 1e-6
// relative (the same method run by two libraries gives errors equal up to round-off,
// and the slower one does not beat the faster). Baselines are left out. Sorted by cost.
struct front_point {
  std::size_t method = 0;
  std::size_t row = 0;
  double cost = 0.0;
  double error = 0.0;
};
std::vector<front_point> pareto_front(const std::vector<wp_method>& methods, bool by_time, bool timed);

// "dt 0.0390625 s" or "tol 1e-08".
std::string format_param(method_kind kind, double param);
// "12.3 us", "4.56 ms"; "n/a" when not finite.
std::string format_time_ns(double ns);

}  // namespace stepbench

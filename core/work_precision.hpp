#pragma once
// The figures derived from the rows of a study: "the cheapest method that reaches an
// error" and the work-precision (Pareto) front. One rule each, used by everything that
// shows them: `stepbench advise`, the study file's equal-error and front tables (which
// the report draws and the README's tables come from) and `stepbench ratios`.
//
// The cheapest-method rule: the cost of each method at equal error, read off its
// measured work-precision curve. A row is on the curve when the run completed (did not
// diverge or fail), its error is finite and positive, its cost is measured and, in a
// timed study, its timing was not cut by the time budget. The cost at a target error is
// interpolated log-log between two rows next to each other on the ladder whose errors
// bracket the target (log cost and log param linear in log error), never extrapolated:
// a method whose coarsest row already meets the target is charged that row's cost (an
// upper bound, flagged `interpolated = false`), and one whose finest row misses it does
// not reach it. Where the curve crosses the target more than once (a pre-asymptotic
// bump, a round-off plateau) the cheapest crossing counts. The repetition spread
// (fastest and slowest repetition) is interpolated the same way, so a comparison can
// say whether two methods differ by more than the noise. Interpolating the curve, as
// work-precision comparisons in the field do (DiffEqDevTools, SciMLBenchmarks), removes
// the factor-2 quantisation of "the cheapest rung that reaches the target" on a halving
// ladder, which flipped verdicts between two runs of the same code.
//
// The cost is the measured time (the median wall time of one whole run) when every
// competing method's curve is timed, else the counted force evaluations. Methods are
// ranked by that cost, then by the error of the row used, then by name. The
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
  bool cut = false;                                           // timing skipped by the time budget
  double time_lo = std::numeric_limits<double>::quiet_NaN();  // fastest repetition (NaN: not recorded)
  double time_hi = std::numeric_limits<double>::quiet_NaN();  // slowest repetition
};

struct wp_method {
  std::string name;
  method_origin origin = method_origin::ours;
  method_kind kind = method_kind::fixed_step;
  std::vector<wp_row> rows;
};

struct wp_pick {
  std::size_t method = 0;                   // index into the input
  std::size_t row = 0;                      // the row used: the finer of the two bracketing rows, or the bounding row
  double cost = 0.0;                        // at equal error: interpolated (or the bounding row's)
  double cost_lo = 0.0, cost_hi = 0.0;      // the repetition spread at equal error (= cost for force evaluations)
  double param = 0.0;                       // the dt or tolerance at equal error, interpolated the same way
  double error = 0.0;                       // the target, or the bounding row's error
  double time_ns = 0.0, force_evals = 0.0;  // both costs at equal error (time NaN when untimed)
  bool interpolated = false;  // between two bracketing rows; false: the coarsest row already met the target
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

// One method's cost at equal error by the rule above; nullopt when no row of its curve
// reaches the target. `by_time`: the cost is time_ns (else force_evals); `timed`: cut
// rows are off the curve. `pick.method` is left 0 for the caller to set.
std::optional<wp_pick> at_equal_error(const wp_method& m, double target, bool by_time, bool timed);

// Two costs at equal error compared with their spreads: "ahead" when a's slowest is
// below b's fastest, "behind" when a's fastest is above b's slowest, else "within
// spread". Counted costs (force evaluations) have no spread; they are equal, not ahead,
// when they agree to 1e-9 relative (the interpolation's rounding).
const char* compare_at_equal_error(const wp_pick& a, const wp_pick& b);
const char* compare_at_equal_error(double a_lo, double a_hi, double b_lo, double b_hi);

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

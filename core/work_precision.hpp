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
// bracket the target (log cost and log param linear in log error), never extrapolated.
// Every measured row at or under the target bounds the cost from above (a method whose
// coarsest row already meets the target is charged that row's cost, flagged
// `interpolated = false`; a row of error exactly 0, a method exact for the problem, is
// such a bound); one whose finest row misses the target does not reach it. Where the curve crosses the target more than
// once (a pre-asymptotic bump, a round-off plateau) the cheapest crossing counts. The repetition spread (fastest and
// slowest repetition) is interpolated the same way, so a comparison can say whether two methods differ by more than the
// noise. Interpolating the curve, as work-precision comparisons in the field do (DiffEqDevTools, SciMLBenchmarks),
// removes the factor-2 quantisation of "the cheapest rung that reaches the target" on a halving ladder, which flipped
// verdicts between two runs of the same code.
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
  bool interpolated = false;  // between two bracketing rows; false: a measured row under the target (a bound)
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

// Timing noise, for `stepbench compare` and the equal-error verdict: a row is flagged when new/old > 1 + threshold
// (slower) or < 1 / (1 + threshold) (faster), threshold = max(floor, 3 x the larger relative spread (max - min) /
// median of the two files' repetitions). The repetitions are taken back to back, so their spread misses the drift
// between two runs (clock, load, cache state of the whole machine): two runs of the same build (stepbench_bench
// --quick, 3 repetitions, a 2-core shared machine) differed by more than 13 % in 5 % of their rows and by more than 23
// % in 1 %, with within-run spreads of a few percent. Hence floor = 15 % when both sides have at least two repetitions,
// and 25 % when a side has a single one (no spread to measure at all).
inline constexpr double timing_noise_floor = 0.15;
inline constexpr double timing_single_run_floor = 0.25;
inline constexpr double timing_spread_multiple = 3.0;

// Two costs at equal error: "ahead" when a / b < 1 / (1 + threshold), "behind" when
// a / b > 1 + threshold, else "within spread", with the threshold of two timings above
// (the larger of the floor and 3 x either side's relative spread (hi - lo) / cost, the
// spread interpolated at equal error; the floor for a single repetition when a side
// has no spread). Back-to-back repetitions miss the drift between runs, which is why
// the spread alone does not decide: two full runs of the same build flipped a verdict
// at 1.05x against 0.86x with spreads of 1 %. Counted costs (force evaluations,
// `timed` false) are exact: equal, not ahead, only within 1e-9 relative (the
// interpolation's rounding).
struct cost_band {
  double cost = 0.0, lo = 0.0, hi = 0.0;
};
const char* compare_at_equal_error(const cost_band& a, const cost_band& b, bool timed);
// The threshold of that comparison: a / b is decided only outside [1 / (1 + t), 1 + t].
double equal_error_threshold(const cost_band& a, const cost_band& b, bool timed);
inline cost_band band_of(const wp_pick& p) { return {p.cost, p.cost_lo, p.cost_hi}; }

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

#pragma once
// Truth and error measurement.
//
// The truth for a problem is its closed form where it has one; every reference is then
// checked against it, and a reference that fails or disagrees is recorded with its
// status and reason (the closed form still holds, so the study goes on). Without a
// closed form the truth is the best-agreeing pair of references (the first of the
// pair in reference order); a reference that disagrees with it is recorded as such. If
// no two references agree within the limit, the problem has no trusted truth: every
// error is NaN and the reason is recorded, rather than measuring against a solver that
// may be wrong.
#include <limits>
#include <string>
#include <vector>

#include "core/problem_instance.hpp"
#include "references/reference.hpp"

namespace stepbench {

// Max over the sample times of |a - b| in position and in velocity, each divided by
// the largest magnitude of the truth's position (velocity) over the run: relative to
// the motion's amplitude, so a zero crossing does not inflate it.
struct agreement {
  double pos_rel = 0.0;
  double vel_rel = 0.0;
  double worst() const { return std::max(pos_rel, vel_rel); }
};

struct reference_check {
  std::string source;
  std::string status = "ok";  // "ok", "failed" (the solver stopped), "disagrees" (beyond the limit)
  std::string reason;         // why, when not ok
  reference_solution solution;
  std::string compared_with;  // "closed_form" or another reference source
  agreement vs;               // this reference against compared_with
};

struct truth_table {
  std::string source;   // "closed_form", the chosen reference, or "none"
  bool trusted = true;  // false: no closed form and no two references agree
  std::string note;     // why the truth is not trusted
  std::vector<double> times;
  std::vector<std::vector<double>> y;  // [x; v] at times (NaN when not trusted)
  std::vector<reference_check> references;
  double pos_scale = 1.0;     // max |x_i| over the bodies, the initial state and the samples
  double vel_scale = 1.0;     // max |v_i| likewise
  double energy_scale = 1.0;  // max of |E| and kinetic energy likewise (see measure.cpp)
  double angmom_scale = 1.0;  // max |L| likewise (problems with an angular momentum)
  double agreement_limit = 0.0;
  // The exact contacts up to the horizon (problems with exact contacts; count -1 without).
  long contact_count = -1;
  std::vector<double> contact_times;
  std::vector<std::vector<double>> contact_positions;
};

struct truth_options {
  bool use_closed_form = true;  // false: measure against the references even where a closed form exists
  bool run_references = true;
  reference_tolerances tol{};
  // Global error of a tolerance-controlled solver runs 10-1000 times its local
  // tolerance; 1e4 * rtol leaves room for that and still catches a broken reference.
  double agreement_limit_factor = 1e4;
  // The references run only when their predicted work (predicted_reference_work) is at
  // most this; above it the truth is "none", not trusted, and the note says why (a scan
  // point whose references would take hours; the sweep keeps the default: no limit).
  double reference_budget = std::numeric_limits<double>::infinity();
};

// What the references' work grows as: the state's coordinates (first-order: 2 x dim)
// times the radians the fastest mode turns over the horizon, w_max T (at least 1; w_max
// from problem.fastest_frequency(), else 2 pi / period(), else 0). Resolving every mode to
// the references' 1e-13 takes a number of steps a radian of it: on spring_chain at 64 and
// 256 masses, k_s 1e5, 3 to 22 steps a radian for each of the four, and their summed time
// grows as this estimate, about 6 us a unit on one core (about 1000 evaluations of one
// coordinate's force: reference_work_in_evaluations).
inline constexpr double reference_work_in_evaluations = 1000.0;
double predicted_reference_work(const problem_instance& problem, double horizon);

// Builds the truth at `times` (increasing, > 0). Throws std::runtime_error only when
// the closed form itself is not finite (parameters out of range).
truth_table build_truth(const problem_instance& problem, std::span<const double> times, const truth_options& opts);

// |a - b| over the `dim` entries from `offset` (|a| when b is empty).
double norm(std::span<const double> a, int offset, int dim, std::span<const double> b = {});

// The largest of any one body's |a_i - b_i| (|a_i| when b is empty): the `dim` entries
// from `offset` in blocks of `body_dim`, one a body (core/concepts.hpp's has_bodies); NaN
// when any is. With one body (body_dim == dim) it is norm(). Every position error and
// amplitude here is one: a player sees the body furthest off, and a stacked norm would
// grow like sqrt(N) on N bodies equally off (docs/measurement.md).
double worst_body(std::span<const double> a, int offset, int dim, int body_dim, std::span<const double> b = {});

agreement compare(std::span<const std::vector<double>> a, std::span<const std::vector<double>> b, int dim, int body_dim,
                  double pos_scale, double vel_scale);

// A row of a study completed: it neither diverged, nor failed, nor was skipped. The one
// statement of the rule; the study file stores the three flags, and every reader (C++
// and the report, through the schema `stepbench schema` prints) applies this.
constexpr bool row_completed(bool diverged, bool failed, bool skipped) { return !diverged && !failed && !skipped; }

struct run_metrics {
  // Position errors are the worst body's (worst_body): |x_i,N - x_i(T)|, Euclidean, in the
  // problem's position unit, on the positions the run draws (run_record's drawn_samples).
  double err_pos_final = 0.0;
  double err_vel_final = 0.0;
  double err_pos_max = 0.0;     // max over the sample times
  double err_pos_rms = 0.0;     // root mean square over the sample times
  double energy_drift = 0.0;    // (E(y_N) - E(y(T))) / energy_scale, signed; NaN without energy
  double energy_err_max = 0.0;  // max over samples of |E(y_j) - E(y(t_j))| / energy_scale
  double angmom_drift = 0.0;    // (L(y_N) - L(y(T))) / angmom_scale, signed; NaN without angular momentum
  double angmom_err_max = 0.0;  // max over samples of |L(y_j) - L(y(t_j))| / angmom_scale; NaN without
  // max over samples of max_j |C_j| / L_j of the run's constraint view: the method's own
  // particles (xpbd), else the state's view (0 for rigid links in generalized coordinates,
  // a spring's stretch); NaN on a problem without a constraint view.
  double constraint_violation_max = 0.0;
  // Contacts (0 and NaN on a problem without them). Errors are matched contact by contact,
  // the k-th of the run with the k-th exact one, over the first min(run's, exact, 64).
  long contacts = 0;               // contacts the run resolved
  double contact_count_err = 0.0;  // contacts - exact contacts up to the horizon (NaN: no exact contacts)
  double contact_time_err = 0.0;   // max |t_k - t_k exact| [s]
  double contact_pos_err = 0.0;    // max |x_k - x_k exact| (position just after contact k)
  long tunnelled = 0;              // contacts found deeper than the problem's tunnelling depth
  double max_penetration = 0.0;    // deepest penetration met before a resolution
  bool diverged = false;           // blew up: non-finite, or beyond blowup_factor x the amplitude
  bool failed = false;             // the method could not complete the run, or there is no trusted truth
  bool skipped = false;            // not run to the end: over the work budget
  std::string note;                // why diverged, failed or skipped

  // The one "row completed" rule: run to the horizon, finite, not over the budget.
  bool completed() const { return row_completed(diverged, failed, skipped); }
};

// Measures a run against the truth. The run's sample times must be the truth's
// times (the sweep's ladder guarantees it; `stepbench run` builds its truth at the
// run's own sample times).
run_metrics measure(const problem_instance& problem, const run_result& run, const truth_table& truth);

// A run whose position error exceeds this many times the motion's amplitude has blown
// up: recorded as diverged, like a NaN. A stable method's error on these bounded
// motions stays within a few amplitudes however coarse its step (a pendulum that an
// energy-gaining method sends over the top reaches some tens); growth past 100 is the
// exponential growth of a step beyond the stability limit.
inline constexpr double blowup_factor = 100.0;

}  // namespace stepbench

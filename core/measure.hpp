#pragma once
// Truth and error measurement.
//
// The truth for a problem is its closed form where it has one; there, every reference
// is checked against it. Without a closed form, the references are checked against
// each other and the truth is the reference that agrees best with the others (the
// smallest worst-case disagreement). Either way a reference that disagrees beyond the
// agreement limit is an error: measuring against a broken reference would make every
// number downstream wrong.
#include <string>
#include <vector>

#include "core/registry.hpp"
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
  reference_solution solution;
  std::string compared_with;  // "closed_form" or another reference source
  agreement vs;               // this reference against compared_with
};

struct truth_table {
  std::string source;  // "closed_form" or the chosen reference
  std::vector<double> times;
  std::vector<std::vector<double>> y;  // [x; v] at times
  std::vector<reference_check> references;
  double pos_scale = 1.0;     // max |x| over the initial state and the samples
  double vel_scale = 1.0;     // max |v| likewise
  double energy_scale = 1.0;  // max of |E| and kinetic energy likewise (see measure.cpp)
};

struct truth_options {
  bool use_closed_form = true;  // false: measure against the references even where a closed form exists
  bool run_references = true;
  reference_tolerances tol{};
  // Global error of a tolerance-controlled solver runs 10-1000 times its local
  // tolerance; 1e4 * rtol leaves room for that and still catches a broken reference.
  double agreement_limit_factor = 1e4;
};

// Builds the truth at `times` (increasing, > 0). Throws std::runtime_error when a
// reference fails or disagrees beyond the limit.
truth_table build_truth(const problem_instance& problem, std::span<const double> times, const truth_options& opts);

agreement compare(std::span<const std::vector<double>> a, std::span<const std::vector<double>> b, int dim,
                  double pos_scale, double vel_scale);

struct run_metrics {
  double err_pos_final = 0.0;  // |x_N - x(T)|, Euclidean, in the problem's position unit
  double err_vel_final = 0.0;
  double err_pos_max = 0.0;    // max over the sample times
  double err_pos_rms = 0.0;    // root mean square over the sample times
  double energy_drift = 0.0;   // (E(y_N) - E(y(T))) / energy_scale, signed; NaN without energy
  double energy_err_max = 0.0; // max over samples of |E(y_j) - E(y(t_j))| / energy_scale
  bool diverged = false;
  std::string diverged_reason;
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

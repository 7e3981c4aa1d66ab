#pragma once
// The convergence sweep: every selected (problem, integrator) over a halving ladder of
// timesteps, measured against the truth, with the observed order fitted.
#include <limits>
#include <map>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include "core/convergence_fit.hpp"
#include "core/measure.hpp"
#include "core/registry.hpp"

namespace stepbench {

struct sweep_options {
  std::vector<std::string> problems;     // empty: all
  std::vector<std::string> integrators;  // empty: all
  // Parameter overrides per problem: overrides["pendulum"]["theta0_deg"] = 30.
  std::map<std::string, std::map<std::string, double>> overrides;
  int levels = 12;       // ladder length (at least 8 for the default study)
  int base_steps = 32;   // steps at the coarsest level; dt_k = T / (base_steps 2^k)
  int sample_count = 32; // fixed sample times j T / sample_count; must divide base_steps
  reference_tolerances tol{};
};

// Wall time of one whole run, from the benchmark (absent unless timed).
struct timing {
  double time_ns = std::numeric_limits<double>::quiet_NaN();  // median over repetitions
  long repetitions = 0;
  bool cut = false;  // skipped by the per-case time budget
};

struct convergence_row {
  double dt = 0.0;
  long steps = 0;
  long force_evals = 0;
  run_metrics metrics;
  timing time;
};

// A peer: what a user might use instead of our methods (GSL, CVODE, Boost.Odeint, a
// hand-inlined loop), run on the same problem and measured against the same truth.
struct peer_row {
  double param = 0.0;  // dt for fixed-step peers, relative tolerance for adaptive ones
  long steps = 0;
  long force_evals = 0;
  double err_pos_final = 0.0;
  double err_pos_max = 0.0;
  bool diverged = false;
  timing time;
};

struct peer_study {
  std::string name;
  std::string kind;  // "fixed_step" or "adaptive"
  std::string description;
  double declared_order = std::numeric_limits<double>::quiet_NaN();
  std::vector<peer_row> rows;
  fit_result fit;  // fixed-step peers only
};

struct integrator_study {
  integrator_info info;
  std::vector<convergence_row> rows;
  fit_result fit;
};

struct problem_study {
  std::unique_ptr<problem_instance> problem;
  double horizon = 0.0;
  truth_table truth;
  std::vector<integrator_study> integrators;
  std::vector<peer_study> peers;
};

// How the timings were taken (present only when the study was timed).
struct timing_settings {
  std::string mode;  // "quick" or "full"
  double min_time_s = 0.0;
  int repetitions = 1;
  double case_budget_s = 0.0;
  int num_cpus = 0;
  double mhz_per_cpu = 0.0;
  int cpu_scaling_enabled = -1;  // 1 on, 0 off, -1 unknown (Google Benchmark's context)
  double wall_seconds = 0.0;
};

struct study {
  sweep_options options;
  std::vector<problem_study> problems;
  double wall_seconds = 0.0;
  std::optional<timing_settings> timed;
};

// Checks the options (names, ladder sizes, overrides) and throws std::invalid_argument
// with a one-line message on the first problem found; run before any work or output.
void validate(const sweep_options& opts);

// The ladder's timesteps for a horizon.
std::vector<double> dt_ladder(double horizon, const sweep_options& opts);

study run_sweep(const sweep_options& opts);

}  // namespace stepbench

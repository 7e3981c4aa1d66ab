#pragma once
// The convergence sweep: every selected (problem, integrator) over a halving ladder of
// timesteps, measured against the truth, with the observed order fitted.
#include <map>
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

struct convergence_row {
  double dt = 0.0;
  long steps = 0;
  long force_evals = 0;
  run_metrics metrics;
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
};

struct study {
  sweep_options options;
  std::vector<problem_study> problems;
  double wall_seconds = 0.0;
};

// Checks the options (names, ladder sizes, overrides) and throws std::invalid_argument
// with a one-line message on the first problem found; run before any work or output.
void validate(const sweep_options& opts);

// The ladder's timesteps for a horizon.
std::vector<double> dt_ladder(double horizon, const sweep_options& opts);

study run_sweep(const sweep_options& opts);

}  // namespace stepbench

#pragma once
// The sweep: every selected method (ours, the peers, the baseline) on every selected
// problem, over a halving ladder of timesteps (fixed-step methods) or a ladder of
// tolerances (adaptive ones), each run measured against the truth by the same code,
// with the observed order fitted. The benchmark adds timings to these rows.
#include <memory>
#include <string>
#include <vector>

#include "registry/registry.hpp"
#include "study/study.hpp"

namespace stepbench {

// The problems the options select, in the study's order: opts.problems, or every problem.
std::vector<std::string> selected_problems(const sweep_options& opts);

// The counted cost of sweeping a problem, computable without running it: its coordinates
// x the fixed-step ladder's steps over the first `levels` levels (base_steps (2^levels -
// 1)) x the methods that run on it (an adaptive method counted as one such ladder), plus
// its reference solves' predicted work (core/measure.hpp predicted_reference_work, in
// coordinate evaluations: x reference_work_in_evaluations).
double sweep_cost(const std::string& problem, const sweep_options& opts);

// The selected problems of shard k of n (0-based), in the study's order: largest counted
// cost first (ties in the study's order), each to the shard with the least cost so far
// (ties to the lowest shard). Deterministic: every machine computes the same split, and a
// shard may hold no problem (n above the selected problems).
std::vector<std::string> sweep_shard(const sweep_options& opts, int k, int n);
// The problems this run sweeps: sweep_shard(opts, opts.shard_index, opts.shard_count).
std::vector<std::string> shard_problems(const sweep_options& opts);

// The threads run_sweep uses for `problems` problems (opts.jobs, 0: one a core).
int sweep_jobs(const sweep_options& opts, std::size_t problems);

// Checks the options (names, ladder sizes, overrides) and throws std::invalid_argument
// with a one-line message on the first problem found; run before any work or output.
void validate(const sweep_options& opts);

// The ladder of a method: a fixed-step one's timesteps for a horizon, to its longest
// (max_levels; its rows are a prefix, at least `levels` long), or the tolerances.
std::vector<double> param_ladder(const method_info& m, double horizon, const sweep_options& opts);

// The problem with its overrides applied and checked.
std::unique_ptr<problem_instance> configured_problem(const std::string& name, const sweep_options& opts);

// Runs one method over its ladder on a problem whose truth is built, measures every
// row and fits the order.
method_study run_method(const problem_study& ps, const method_info& m, const sweep_options& opts);

// Fits the observed order (or, for adaptive methods, the slope of error against the
// tolerance) from the rows, and checks it against the declared order.
void fit_rows(method_study& ms, double pos_scale);

}  // namespace stepbench

#pragma once
// The game-loop study's runs (study/loop.hpp says what it measures).
#include <string>
#include <string_view>

#include "study/study.hpp"

namespace stepbench {

// The exact state at the frames' display times: the closed form, or the references
// (build_truth) where there is none.
truth_table loop_truth(const problem_instance& problem, const loop_result& run);

// Measures a simulated run against the truth at its display times; `reference` is the
// same configuration on the reference clock (nullptr: frame-rate independence NaN).
loop_row measure_loop(const loop_config& config, std::string clock, const loop_result& run, const truth_table& truth,
                      const loop_result* reference);

// One configuration as `stepbench loop --design` runs it: simulated, its reference clock
// simulated, measured. Throws std::invalid_argument for bad input.
loop_row run_loop_config(const problem_instance& problem, std::string_view method, const loop_config& config,
                         const loop_options& opts);

// Every configuration of the study for one integrator on one problem.
loop_method run_loop_method(const problem_instance& problem, const method_info& method, const loop_options& opts);

// The loop study of the problems of `s` that the options name (with their overrides).
loop_study run_loop_study(const study& s, const loop_options& opts);

}  // namespace stepbench

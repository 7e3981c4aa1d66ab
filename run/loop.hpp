#pragma once
// The game-loop study's runs (study/loop.hpp says what it measures).
#include <string>
#include <string_view>

#include "study/study.hpp"

namespace stepbench {

// One configuration as `stepbench loop --design` runs it: simulated, its reference clock
// simulated, measured. Throws std::invalid_argument for bad input.
loop_row run_loop_config(const problem_instance& problem, std::string_view method, const loop_config& config,
                         const loop_options& opts);

// Every configuration of the study for one integrator on one problem.
loop_method run_loop_method(const problem_instance& problem, const method_info& method, const loop_options& opts);

// The loop study of the problems of `s` that the options name (with their overrides).
loop_study run_loop_study(const study& s, const loop_options& opts);

}  // namespace stepbench

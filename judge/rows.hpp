#pragma once
// A study's rows in the shapes the judges take them.
#include <string>
#include <vector>

#include "core/work_precision.hpp"
#include "study/study.hpp"

namespace stepbench {

// One error metric of a run by its name: err_pos_max, err_pos_final, err_pos_rms,
// err_vel_final (std::logic_error for another: a bug, not input).
double metric_value(const run_metrics& m, const std::string& metric);

// The rows of a problem's methods in the shape the work-precision rule takes, for one
// error metric (core/work_precision.hpp).
std::vector<wp_method> work_precision_input(const problem_study& ps, const std::string& metric);

}  // namespace stepbench

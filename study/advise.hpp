#pragma once
// `stepbench advise`: answers "which method, at which dt (or tolerance), for this
// error?" from a study file (docs/study-format.md), without running anything, by the
// cheapest-method rule of core/work_precision.hpp (the same rule as the study file's
// equal-error table and `stepbench ratios`). A method that diverged at a coarser dt
// than its chosen row is still a candidate (it is stable at the chosen dt); the largest
// dt at which it diverged is reported as its stability margin. The hand-written
// baseline is shown for scale, marked as such, and is never the answer.
//
// Exit codes of the subcommand: 0 an answer; 1 the study file is missing or
// unreadable; 2 bad usage (unknown problem or metric, tol not a positive finite
// number); 3 no method in the file meets the tolerance (the best achieved is printed).
#include <string>
#include <vector>

#include "core/work_precision.hpp"
#include "study/study_reader.hpp"

namespace stepbench {

inline constexpr int advise_exit_no_method = 3;

struct advice {
  std::string problem, metric, unit;
  double tol = 0.0;
  bool timed = false;
  std::vector<wp_method> methods;
  cheapest_result result;
  bool met() const { return result.answer(methods).has_value(); }
};

// Throws std::invalid_argument for an unknown metric or a problem the file lacks
// (naming the problems it has), or a tol that is not a positive finite number.
advice advise(const study_data& study, const std::string& problem, const std::string& metric, double tol);

// The human-readable answer (several lines, ends with a newline).
std::string format_advice(const advice& a, std::size_t runners_up = 5);

}  // namespace stepbench

#pragma once
// A scan's runs (study/scan.hpp says what it answers): its axes parsed and checked, its
// grid, its shards and their merge.
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "study/scan.hpp"

namespace stepbench {

// Parses `P.name=lo:hi:count[:log]` for problem P; throws std::invalid_argument with a
// one-line reason (another problem, an unknown parameter, a bound outside the parameter's
// declared range, count < 1 or above 10^5, log with a bound <= 0).
scan_axis parse_scan_axis(std::string_view text, const std::string& problem);

// Checks the options; throws std::invalid_argument with a one-line reason.
void validate(const scan_options& opts);

// The scans of the full study: stiff_spring over k_s 1e1 .. 1e7 N/m (25 points, log), the
// pendulum over its release angle 1 .. 179.9 deg (12 points) and spring_chain over 8 .. 4096
// masses x k_s 1e2 .. 1e5 N/m (4 x 4, log), each at 30 .. 240 Hz with 1 .. 64 substeps;
// `quick`: the stiff spring's 13 points at 60 Hz only (the CI study).
std::vector<scan_options> default_scans(bool quick = false);

scan_result run_scan(const scan_options& opts);

// `advise --hz H --time`: each of the scan's methods' ns per force evaluation, timed here on
// the scan's scene (its problem and --set values, no axes) rather than read from a timed
// study: the median over five batches of whole runs of a few frames at the finest dt the
// scan runs (hz x the most substeps), each batch at least 10 ms, divided by the run's counted
// force evaluations. A method whose run does not complete is timed on what it ran. About a
// second on a default scene.
std::map<std::string, double> eval_costs_timed_here(const scan_options& opts);

// The grid points in order: the first axis varies slowest.
std::vector<std::vector<double>> scan_grid(const std::vector<scan_axis>& axes);

}  // namespace stepbench

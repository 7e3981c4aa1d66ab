#pragma once
// The frame-rate study (study/verdict.hpp says what it answers): our fixed-step methods at
// whole frames of each rate, n substeps a frame, measured at the frame ends.
#include <string>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// The frames at rates `hz` within a problem's horizon: whole frames of the slowest rate (at
// least one), the truth's times at the fastest rate's frame ends (every rate divides the
// fastest). The frame-rate study's and the scan's.
struct frames {
  double horizon = 0.0;
  std::vector<double> times;
};
frames frames_of(double problem_horizon, const std::vector<double>& hz);

// Every frame end is a truth sample and a sample of each run, of every coordinate: their
// count bounds a frame-rate run's memory (a scan at --hz 1e9 asked for 5e9 frame ends
// and grew past 8 GB). At most 1e7 frame ends, and 2e7 frame ends x coordinates (160 MB
// a table; the default scans' largest, the rope of 4096 masses at 240 Hz, is 1.6e6).
inline constexpr double max_frame_ends = 1e7, max_frame_coordinates = 2e7;
// "" when the frame ends of `hz` over `problem_horizon` are within both bounds, else why not.
std::string frames_over_limit(double problem_horizon, const std::vector<double>& hz, double coordinates);

// The truth at every stride-th sample of `t` (the frame ends of a slower rate).
truth_table every_nth(const truth_table& t, std::size_t stride);

// Runs the frame-rate study on every problem of `s` (their truths are rebuilt at the frame
// ends of the fastest rate). A problem whose horizon holds no whole frame is left out.
std::vector<frame_rate_study> run_frame_rates(const study& s, const frame_rate_options& opts);

}  // namespace stepbench

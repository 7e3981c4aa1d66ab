#include "run/frame_rates.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/contains.hpp"
#include "core/measure.hpp"

namespace stepbench {

namespace {
// Whole frames of the slowest rate (at least one) and the horizon they span.
double whole_frames_horizon(double problem_horizon, const std::vector<double>& hz) {
  const double slowest = *std::min_element(hz.begin(), hz.end());
  return std::max(1.0, std::floor(problem_horizon * slowest * (1.0 + 1e-12))) / slowest;
}
}  // namespace

std::string frames_over_limit(double problem_horizon, const std::vector<double>& hz, double coordinates) {
  const double fastest = *std::max_element(hz.begin(), hz.end());
  const double ends = whole_frames_horizon(problem_horizon, hz) * fastest;
  if (!(ends <= max_frame_ends))
    return fmt::format("{:.3g} frame ends ({:g} Hz over {:.3g} s); the limit is {:g}", ends, fastest, problem_horizon,
                       max_frame_ends);
  if (!(ends * coordinates <= max_frame_coordinates))
    return fmt::format("{:.3g} frame ends x {:g} coordinates ({:g} Hz over {:.3g} s) = {:.3g}; the limit is {:g}", ends,
                       coordinates, fastest, problem_horizon, ends * coordinates, max_frame_coordinates);
  return "";
}

frames frames_of(double problem_horizon, const std::vector<double>& hz) {
  if (!(problem_horizon * *std::max_element(hz.begin(), hz.end()) <= 2 * max_frame_ends))
    throw std::invalid_argument(frames_over_limit(problem_horizon, hz, 1.0));  // callers check first
  const double fastest = *std::max_element(hz.begin(), hz.end());
  frames f;
  f.horizon = whole_frames_horizon(problem_horizon, hz);
  const long fast_frames = std::lround(f.horizon * fastest);
  for (long j = 1; j <= fast_frames; ++j) f.times.push_back(static_cast<double>(j) / fastest);
  return f;
}

truth_table every_nth(const truth_table& t, std::size_t stride) {
  truth_table out = t;
  out.times.clear();
  out.y.clear();
  for (std::size_t j = stride - 1; j < t.times.size(); j += stride) {
    out.times.push_back(t.times[j]);
    out.y.push_back(t.y[j]);
  }
  return out;
}

std::vector<frame_rate_study> run_frame_rates(const study& s, const frame_rate_options& opts) {
  std::vector<frame_rate_study> out;
  if (opts.hz.empty()) return out;
  const double slowest = *std::min_element(opts.hz.begin(), opts.hz.end());
  const double fastest = *std::max_element(opts.hz.begin(), opts.hz.end());
  const double finest_target = verdict_targets().back();
  for (const auto& ps : s.problems) {
    if (!ps.truth.trusted) continue;
    if (static_cast<long>(std::floor(ps.horizon * slowest * (1.0 + 1e-12))) < 1) continue;  // no whole frame
    if (const auto why = frames_over_limit(ps.horizon, opts.hz, ps.problem->dim()); !why.empty()) {
      std::fprintf(stderr, "frame rates: %s left out: %s\n", std::string(ps.problem->name()).c_str(), why.c_str());
      continue;
    }
    const frames f = frames_of(ps.horizon, opts.hz);
    frame_rate_study fs;
    fs.problem = std::string(ps.problem->name());
    fs.unit = std::string(ps.problem->position_unit());
    fs.horizon = f.horizon;
    const truth_table fine = build_truth(*ps.problem, f.times, {.tol = s.options.tol});
    if (!fine.trusted) continue;
    for (double hz : opts.hz) {
      const auto stride = static_cast<std::size_t>(std::lround(fastest / hz));
      const truth_table truth = every_nth(fine, stride);
      for (const auto& info : ps.problem->methods()) {
        if (!offered_as_ours(info.origin) || info.kind != method_kind::fixed_step) continue;
        if (!s.options.methods.empty() && !contains(s.options.methods, info.name)) continue;
        for (int n : opts.substeps) {
          const double dt = 1.0 / (hz * n);
          const run_result run = ps.problem->run(info.name, dt, fs.horizon, truth.times, s.options.limits);
          frame_rate_run r{
              hz, info.name, n, {dt, run.steps, run.rejected_steps, run.work, measure(*ps.problem, run, truth), {}}};
          const bool done =
              r.row.metrics.skipped || (r.row.metrics.completed() && r.row.metrics.err_pos_max <= finest_target);
          fs.runs.push_back(std::move(r));
          if (done) break;  // over the work budget, or already at the finest target
        }
      }
    }
    if (s.options.progress) std::fprintf(stderr, "frame rates %-20s %zu runs\n", fs.problem.c_str(), fs.runs.size());
    out.push_back(std::move(fs));
  }
  return out;
}

}  // namespace stepbench

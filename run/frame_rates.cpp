#include "run/frame_rates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/contains.hpp"
#include "core/measure.hpp"

namespace stepbench {

frames frames_of(double problem_horizon, const std::vector<double>& hz) {
  const double slowest = *std::min_element(hz.begin(), hz.end());
  const double fastest = *std::max_element(hz.begin(), hz.end());
  frames f;
  const long slow_frames = std::max(1L, static_cast<long>(std::floor(problem_horizon * slowest * (1.0 + 1e-12))));
  f.horizon = static_cast<double>(slow_frames) / slowest;
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
        if (info.origin != method_origin::ours || info.kind != method_kind::fixed_step) continue;
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

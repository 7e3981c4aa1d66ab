#include "judge/loop.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/number.hpp"
#include "core/statistics.hpp"

namespace stepbench {

loop_cost cost_verdict(const loop_config& config, double step_cost_ns, std::string source) {
  loop_cost out;
  out.step_cost_ns = step_cost_ns;
  out.source = std::move(source);
  out.schedule = schedule_loop(config, step_cost_ns * 1e-9);
  out.without_clamp = out.schedule.outcome;
  if (config.clamp_s > 0.0) {
    loop_config off = config;
    off.clamp_s = 0.0;
    out.without_clamp = schedule_loop(off, step_cost_ns * 1e-9).outcome;
  }
  out.clamp_prevented_spiral =
      config.clamp_s > 0.0 && out.schedule.outcome != loop_outcome::spiral && out.without_clamp == loop_outcome::spiral;
  return out;
}

double measured_step_cost_ns(const problem_study& ps, std::string_view method) {
  for (const auto& ms : ps.methods) {
    if (ms.info.name != method) continue;
    std::vector<double> per_step;
    for (const auto& r : ms.rows)
      if (r.metrics.completed() && r.steps > 0 && std::isfinite(r.time.time_ns) && r.time.time_ns > 0.0)
        per_step.push_back(r.time.time_ns / static_cast<double>(r.steps));
    return median(per_step);
  }
  return nan;
}

std::vector<loop_cheapest> cheapest_designs(const loop_method& m, const loop_options& opts) {
  static constexpr std::array preference{loop_design::fixed, loop_design::interpolated, loop_design::substeps,
                                         loop_design::variable};
  auto rank = [](loop_design d) { return std::find(preference.begin(), preference.end(), d) - preference.begin(); };
  // Fewest steps a frame, then the smaller error, then the design preferred.
  const auto key = [&](const loop_row& r) {
    return std::tuple(r.steps_per_frame_mean, r.shown_err_max, rank(r.config.design));
  };
  std::vector<loop_cheapest> out;
  for (double hz : opts.display_hz) {
    const loop_row* best = nullptr;
    for (const auto& r : m.rows)
      if (r.clock == "constant" && r.config.display_hz == hz && !r.diverged && r.shown_err_max <= opts.target &&
          (!best || key(r) < key(*best)))
        best = &r;
    out.push_back({hz, opts.target, best != nullptr, best ? std::string(to_string(best->config.design)) : "",
                   !best || best->config.design == loop_design::variable ? nan : best->config.physics_hz,
                   best ? best->steps_per_frame_mean : nan, best ? best->shown_err_max : nan});
  }
  return out;
}

}  // namespace stepbench

#include "judge/loop.hpp"

#include <algorithm>
#include <cmath>

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
  std::vector<loop_cheapest> out;
  for (double hz : opts.display_hz) {
    loop_cheapest c;
    c.display_hz = hz;
    c.target = opts.target;
    c.physics_hz = c.steps_per_frame_mean = c.shown_err_max = nan;
    const loop_row* best = nullptr;
    for (const auto& r : m.rows) {
      if (r.clock != "constant" || r.config.display_hz != hz || r.diverged || !(r.shown_err_max <= opts.target))
        continue;
      if (!best || r.steps_per_frame_mean < best->steps_per_frame_mean ||
          (r.steps_per_frame_mean == best->steps_per_frame_mean &&
           (r.shown_err_max < best->shown_err_max ||
            (r.shown_err_max == best->shown_err_max && rank(r.config.design) < rank(best->config.design)))))
        best = &r;
    }
    if (best) {
      c.found = true;
      c.design = to_string(best->config.design);
      c.physics_hz = best->config.design == loop_design::variable ? nan : best->config.physics_hz;
      c.steps_per_frame_mean = best->steps_per_frame_mean;
      c.shown_err_max = best->shown_err_max;
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace stepbench

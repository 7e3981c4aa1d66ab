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

namespace {
// The median over `method`'s timed rows that completed of time / count(row); NaN when it
// has none (the study untimed, or the method not run).
template <class Count>
double median_time_per(const problem_study& ps, std::string_view method, Count count) {
  const method_study* ms = ps.find(method);
  if (!ms) return nan;
  std::vector<double> per;
  for (const auto& r : ms->rows)
    if (const double n = count(r);
        r.metrics.completed() && n > 0 && std::isfinite(r.time.time_ns) && r.time.time_ns > 0.0)
      per.push_back(r.time.time_ns / n);
  return median(per);
}
}  // namespace

double measured_step_cost_ns(const problem_study& ps, std::string_view method) {
  return median_time_per(ps, method, [](const method_row& r) { return static_cast<double>(r.steps); });
}

double measured_eval_cost_ns(const problem_study& ps, std::string_view method) {
  return median_time_per(ps, method, [](const method_row& r) { return static_cast<double>(r.work.force_evals); });
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

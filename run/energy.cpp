#include "run/energy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/number.hpp"
#include "run/sweep.hpp"

namespace stepbench {
namespace {

// Least-squares slope of y against k = 1..n.
double slope(const std::vector<double>& y) {
  const double n = static_cast<double>(y.size());
  if (y.size() < 2) return nan;
  const double k_mean = 0.5 * (n + 1.0);
  double y_mean = 0.0;
  for (double v : y) y_mean += v;
  y_mean /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t j = 0; j < y.size(); ++j) {
    const double dk = static_cast<double>(j + 1) - k_mean;
    sxy += dk * (y[j] - y_mean);
    sxx += dk * dk;
  }
  return sxy / sxx;
}

energy_run run_one(const problem_instance& p, const method_info& m, const energy_problem& ep, const energy_options& o) {
  energy_run out;
  out.info = m;
  out.dt = ep.dt;
  const int per = o.samples_per_period;
  const long stride = ep.steps_per_period / per;  // steps between samples
  const long samples = static_cast<long>(std::llround(o.periods)) * per;
  std::vector<double> times;
  times.reserve(static_cast<std::size_t>(samples));
  for (long j = 1; j <= samples; ++j) times.push_back(static_cast<double>(j * stride) * ep.dt);  // the grid's own times
  run_limits limits;
  limits.work_budget = std::numeric_limits<double>::infinity();  // this study states its own dt
  const auto start = std::chrono::steady_clock::now();
  const run_result r = p.run(m.name, ep.dt, ep.horizon, times, limits);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.steps = r.steps;
  out.force_evals = r.work.force_evals;
  if (!r.stop_reason.empty() || r.non_finite || r.sample_y.size() != times.size()) {
    out.note = !r.stop_reason.empty() ? r.stop_reason : "non-finite state";
    out.max_rel_err = out.final_rel_err = out.drift_per_period = out.angmom_max_rel_err = out.angmom_drift_per_period =
        out.first_tenth_max = out.last_tenth_max = out.last_tenth_mean = nan;
    return out;
  }
  out.completed = true;
  const double e_scale = std::abs(ep.e0), l_scale = std::abs(ep.l0);
  const bool has_l = p.has_angular_momentum();
  // Each period's peak error (signed): the sample of largest magnitude in the period.
  std::vector<double> err(times.size()), period_peak, l_period_peak;
  double l_max = 0.0;
  auto keep_peak = [](std::vector<double>& peaks, bool new_period, double e) {
    if (new_period)
      peaks.push_back(e);
    else if (std::abs(e) > std::abs(peaks.back()))
      peaks.back() = e;
  };
  for (std::size_t j = 0; j < times.size(); ++j) {
    const bool new_period = j % static_cast<std::size_t>(per) == 0;
    err[j] = (p.energy(r.sample_y[j]) - ep.e0) / e_scale;
    out.max_rel_err = std::max(out.max_rel_err, std::abs(err[j]));
    keep_peak(period_peak, new_period, err[j]);
    if (has_l) {
      const double dl = (p.angular_momentum(r.sample_y[j]) - ep.l0) / l_scale;
      l_max = std::max(l_max, std::abs(dl));
      keep_peak(l_period_peak, new_period, dl);
    }
  }
  if (!std::isfinite(out.max_rel_err)) {
    out.completed = false;
    out.note = "non-finite energy";
  }
  out.final_rel_err = err.back();
  out.drift_per_period = slope(period_peak);
  out.angmom_max_rel_err = has_l ? l_max : nan;
  out.angmom_drift_per_period = has_l ? slope(l_period_peak) : nan;
  const std::size_t tenth = std::max<std::size_t>(1, err.size() / 10);
  for (std::size_t j = 0; j < tenth; ++j) out.first_tenth_max = std::max(out.first_tenth_max, std::abs(err[j]));
  double sum = 0.0;
  for (std::size_t j = err.size() - tenth; j < err.size(); ++j) {
    out.last_tenth_max = std::max(out.last_tenth_max, std::abs(err[j]));
    sum += err[j];
  }
  out.last_tenth_mean = sum / static_cast<double>(tenth);
  const bool bounded =
      out.completed && out.last_tenth_max <= o.bounded_growth * out.first_tenth_max && out.max_rel_err < o.lost;
  out.verdict = !out.completed ? "" : bounded ? "bounded" : "drifting";
  out.drift_sign = bounded || !out.completed ? 0 : (out.last_tenth_mean > 0.0 ? 1 : -1);

  // The error curve for a log time axis: series_points bins log-spaced in sample index,
  // each stored as its time and the signed error of largest magnitude in it.
  const double n = static_cast<double>(err.size());
  std::size_t from = 0;
  for (int b = 1; b <= o.series_points && from < err.size(); ++b) {
    const auto to = std::max(
        from + 1, std::min(err.size(),
                           static_cast<std::size_t>(std::ceil(std::pow(n, static_cast<double>(b) / o.series_points)))));
    std::size_t worst = from;
    for (std::size_t j = from; j < to; ++j)
      if (std::abs(err[j]) > std::abs(err[worst])) worst = j;
    out.series_t.push_back(times[worst]);
    out.series_err.push_back(err[worst]);
    from = to;
  }
  return out;
}

}  // namespace

energy_study run_energy_study(const energy_options& opts,
                              const std::map<std::string, std::map<std::string, double>>& overrides) {
  const auto start = std::chrono::steady_clock::now();
  energy_study s;
  s.options = opts;
  if (!(opts.periods >= 1 && opts.periods <= 1e7 && opts.periods == std::floor(opts.periods)))
    throw std::invalid_argument("energy study: periods must be a whole number from 1 to 1e7");
  if (opts.samples_per_period < 1 || opts.series_points < 2)
    throw std::invalid_argument("energy study: samples_per_period >= 1 and series_points >= 2");
  for (const auto& scene : opts.scenes) {
    const auto t0 = std::chrono::steady_clock::now();
    sweep_options configure;
    configure.overrides = overrides;
    for (const auto& [name, value] : scene.params) configure.overrides[scene.problem].try_emplace(name, value);
    if (scene.steps_per_period < 1 || scene.steps_per_period % opts.samples_per_period != 0)
      throw std::invalid_argument(fmt::format("energy study: {}: steps_per_period must be a positive multiple of {}",
                                              scene.problem, opts.samples_per_period));
    const auto p = configured_problem(scene.problem, configure);
    if (!p->has_energy())
      throw std::invalid_argument(fmt::format("energy study: problem {} has no energy to follow", scene.problem));
    // The problem's period; else the one given (--period); else its horizon, after --set.
    const double period = std::isfinite(p->period())    ? p->period()
                          : std::isfinite(scene.period) ? scene.period
                                                        : p->horizon();
    energy_problem ep;
    ep.problem = scene.problem;
    ep.params = p->params();
    ep.period = period;
    ep.steps_per_period = scene.steps_per_period;
    ep.dt = ep.period / scene.steps_per_period;
    ep.horizon = static_cast<double>(std::llround(opts.periods) * scene.steps_per_period) * ep.dt;
    const auto y0 = p->initial();
    ep.e0 = p->energy(y0);
    if (!(ep.e0 != 0.0))  // dE/E is relative to E0
      throw std::invalid_argument(
          fmt::format("energy study: problem {} starts with zero energy: dE/E has no scale", scene.problem));
    ep.l0 = p->has_angular_momentum() ? p->angular_momentum(y0) : nan;
    for (const auto& m : p->methods())
      if (offered_as_ours(m.origin) && m.kind == method_kind::fixed_step &&
          (opts.methods.empty() || std::find(opts.methods.begin(), opts.methods.end(), m.name) != opts.methods.end()))
        ep.runs.push_back(run_one(*p, m, ep, opts));
    if (opts.progress)
      std::fprintf(stderr, "energy  %-22s %3zu methods over %g periods in %.2f s\n", scene.problem.c_str(),
                   ep.runs.size(), opts.periods,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    s.problems.push_back(std::move(ep));
  }
  s.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace stepbench

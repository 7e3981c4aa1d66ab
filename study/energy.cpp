#include "study/energy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/number.hpp"
#include "study/h5.hpp"
#include "study/study_file.hpp"
#include "study/sweep.hpp"

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
    if (!std::isfinite(p->period()) || !p->has_energy())
      throw std::invalid_argument(fmt::format("energy study: problem {} has no period or no energy", scene.problem));
    energy_problem ep;
    ep.problem = scene.problem;
    ep.params = p->params();
    ep.period = p->period();
    ep.steps_per_period = scene.steps_per_period;
    ep.dt = ep.period / scene.steps_per_period;
    ep.horizon = static_cast<double>(std::llround(opts.periods) * scene.steps_per_period) * ep.dt;
    const auto y0 = p->initial();
    ep.e0 = p->energy(y0);
    ep.l0 = p->has_angular_momentum() ? p->angular_momentum(y0) : nan;
    for (const auto& m : p->methods())
      if (m.origin == method_origin::ours && m.kind == method_kind::fixed_step &&
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

void write_energy(H5::Group& root, const energy_study& s) {
  if (s.problems.empty()) return;
  using h5::attr;
  H5::Group g = root.createGroup("energy");
  const auto& o = s.options;
  attr(g, "periods", o.periods);
  attr(g, "samples_per_period", o.samples_per_period);
  attr(g, "series_points", o.series_points);
  attr(g, "bounded_growth", o.bounded_growth);
  attr(g, "lost", o.lost);
  attr(g, "rule",
       fmt::format("bounded: the largest |E - E0| / |E0| over the last tenth of the run is at most {:g} times the "
                   "largest over the first tenth, and every error is below {:g}; drifting otherwise, its sign that "
                   "of the mean error over the last tenth",
                   o.bounded_growth, o.lost));
  attr(g, "wall_seconds", s.wall_seconds);
  for (const auto& ep : s.problems) {
    H5::Group pg = g.createGroup(ep.problem);
    parameters_table(ep.params).write(pg, "parameters", schema::find("parameters"));
    attr(pg, "period", ep.period);
    attr(pg, "dt", ep.dt);
    attr(pg, "steps_per_period", ep.steps_per_period);
    attr(pg, "horizon", ep.horizon);
    attr(pg, "energy0", ep.e0);
    attr(pg, "angular_momentum0", ep.l0);
    h5::table t;
    auto col = [&](auto get) {
      using T = decltype(get(ep.runs.front()));
      std::vector<T> v;
      for (const auto& r : ep.runs) v.push_back(get(r));
      return v;
    };
    t.add("method", col([](const energy_run& r) { return r.info.name; }));
    t.add("symplectic", col([](const energy_run& r) { return static_cast<std::int8_t>(r.info.traits.symplectic); }));
    t.add("dt", col([](const energy_run& r) { return r.dt; }));
    t.add("steps", col([](const energy_run& r) { return std::int64_t{r.steps}; }));
    t.add("force_evals", col([](const energy_run& r) { return std::int64_t{r.force_evals}; }));
    t.add("completed", col([](const energy_run& r) { return static_cast<std::int8_t>(r.completed); }));
    t.add("max_rel_err", col([](const energy_run& r) { return r.max_rel_err; }));
    t.add("final_rel_err", col([](const energy_run& r) { return r.final_rel_err; }));
    t.add("drift_per_period", col([](const energy_run& r) { return r.drift_per_period; }));
    t.add("first_tenth_max", col([](const energy_run& r) { return r.first_tenth_max; }));
    t.add("last_tenth_max", col([](const energy_run& r) { return r.last_tenth_max; }));
    t.add("last_tenth_mean", col([](const energy_run& r) { return r.last_tenth_mean; }));
    t.add("verdict", col([](const energy_run& r) { return r.verdict; }));
    t.add("drift_sign", col([](const energy_run& r) { return std::int64_t{r.drift_sign}; }));
    t.add("angmom_max_rel_err", col([](const energy_run& r) { return r.angmom_max_rel_err; }));
    t.add("angmom_drift_per_period", col([](const energy_run& r) { return r.angmom_drift_per_period; }));
    t.add("seconds", col([](const energy_run& r) { return r.seconds; }));
    t.add("note", col([](const energy_run& r) { return r.note; }));
    t.write(pg, "summary", schema::find("energy_summary"));
    H5::Group series = pg.createGroup("series");
    for (const auto& r : ep.runs) {
      if (!r.completed) continue;
      H5::Group mg = series.createGroup(r.info.name);
      h5::dataset(mg, "time", r.series_t);
      h5::dataset(mg, "energy_error", r.series_err);
    }
  }
}

}  // namespace stepbench

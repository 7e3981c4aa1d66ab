#include "study/loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/contains.hpp"
#include "core/number.hpp"
#include "core/statistics.hpp"
#include "study/h5.hpp"
#include "study/sweep.hpp"

namespace stepbench {
namespace {

double distance(const double* a, const double* b, int dim) {
  double s = 0.0;
  for (int i = 0; i < dim; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(s);
}

// The truths of one problem's runs, by their display times: every design and physics
// rate on one clock shows its frames at the same times, so each clock's truth is built
// once.
class truth_cache {
 public:
  explicit truth_cache(const problem_instance& p) : problem_(p) {}
  const truth_table& at(const loop_result& run) {
    for (const auto& [times, truth] : entries_)
      if (times == run.display_t) return truth;
    entries_.emplace_back(run.display_t, loop_truth(problem_, run));
    return entries_.back().second;
  }

 private:
  const problem_instance& problem_;
  std::vector<std::pair<std::vector<double>, truth_table>> entries_;
};

// The study's clocks for a run of `horizon`: constant at each display rate, jittered,
// and the stall with the clamp and without it. The clamp is on everywhere else (it
// never cuts a frame of those clocks).
struct clock_case {
  std::string name;
  loop_config config;
};
std::vector<clock_case> study_clocks(const loop_config& base, double horizon, const loop_options& o) {
  std::vector<clock_case> out;
  loop_config c = base;
  c.horizon = horizon;
  c.clamp_s = o.clamp_s;
  c.jitter = o.jitter;
  c.stall_s = o.stall_s;
  for (double hz : o.display_hz) {
    c.display_hz = hz;
    out.push_back({"constant", c});
  }
  c.display_hz = o.reference_display_hz;
  loop_config j = c;
  j.jitter_seed = o.jitter_seed;
  out.push_back({"jitter", j});
  loop_config st = c;
  st.stall_at_s = o.stall_at_fraction * horizon;
  out.push_back({"stall", st});
  st.clamp_s = 0.0;
  out.push_back({"stall", st});
  return out;
}

// The reference clock of a configuration: constant at the reference rate, no jitter,
// no stall, the same design, physics rate and clamp.
loop_config reference_of(loop_config c, const loop_options& o) {
  c.display_hz = o.reference_display_hz;
  c.jitter_seed.reset();
  c.stall_at_s = nan;
  return c;
}

bool same_run(const loop_config& a, const loop_config& b) {
  return a.design == b.design && a.display_hz == b.display_hz && a.physics_hz == b.physics_hz &&
         a.clamp_s == b.clamp_s && a.jitter_seed == b.jitter_seed && (a.jitter_seed ? a.jitter == b.jitter : true) &&
         ((std::isnan(a.stall_at_s) && std::isnan(b.stall_at_s)) ||
          (a.stall_at_s == b.stall_at_s && a.stall_s == b.stall_s)) &&
         a.horizon == b.horizon;
}

void check_truth_times(const truth_table& truth, const loop_result& run) {
  if (truth.times != run.display_t) throw std::logic_error("measure_loop: the truth's times are not the run's frames");
}

// Steps per frame over the counted frames, the stall's burst, the clamp, the clock's lag
// and the interpolation factor's range.
void count_steps(loop_row& row, const loop_config& config, const loop_result& run, std::size_t counted) {
  long steps = 0;
  row.alpha_min = row.alpha_max = nan;
  double lag_clock = 0.0;
  for (std::size_t j = 0; j < counted; ++j) {
    steps += run.steps[j];
    row.steps_per_frame_max = std::max<long>(row.steps_per_frame_max, run.steps[j]);
    if (run.stall[j]) row.stall_burst_steps = run.steps[j];
    row.clamp_hits += run.clamped[j];
    lag_clock += run.display_t[j] - run.shown_t[j];
    if (uses_accumulator(config.design)) {
      row.alpha_min = j == 0 ? run.alpha[j] : std::min(row.alpha_min, run.alpha[j]);
      row.alpha_max = j == 0 ? run.alpha[j] : std::max(row.alpha_max, run.alpha[j]);
    }
  }
  row.steps_per_frame_mean = counted ? static_cast<double>(steps) / static_cast<double>(counted) : nan;
  row.lag_clock_s = counted ? lag_clock / static_cast<double>(counted) : nan;
}

// Judder: the spread (RMS about the mean) of (shown - exact) velocity over the counted
// frames, each velocity the finite difference of positions over the display time
// between consecutive frames. NaN with fewer than two pairs of frames.
double judder(const loop_result& run, const truth_table& truth, std::size_t counted) {
  const int dim = run.dim;
  std::vector<double> d;  // (shown - exact) velocity differences, dim per pair
  for (std::size_t j = 1; j < counted; ++j) {
    const double h = run.display_t[j] - run.display_t[j - 1];
    for (int i = 0; i < dim; ++i) {
      const double shown = run.shown[j * dim + i] - run.shown[(j - 1) * dim + i];
      const double exact = truth.y[j][i] - truth.y[j - 1][i];
      d.push_back((shown - exact) / h);
    }
  }
  const std::size_t pairs = d.size() / std::max(dim, 1);
  if (pairs < 2) return nan;
  std::vector<double> mean(dim, 0.0);
  for (std::size_t p = 0; p < pairs; ++p)
    for (int i = 0; i < dim; ++i) mean[i] += d[p * dim + i] / static_cast<double>(pairs);
  double var = 0.0;
  for (std::size_t p = 0; p < pairs; ++p)
    for (int i = 0; i < dim; ++i) var += (d[p * dim + i] - mean[i]) * (d[p * dim + i] - mean[i]);
  return std::sqrt(var / static_cast<double>(pairs));
}

}  // namespace

truth_table loop_truth(const problem_instance& problem, const loop_result& run) {
  truth_options opts;
  opts.run_references = !problem.has_closed_form();
  return build_truth(problem, run.display_t, opts);
}

loop_row measure_loop(const loop_config& config, std::string clock, const loop_result& run, const truth_table& truth,
                      const loop_result* reference) {
  loop_row row;
  row.config = config;
  row.clock = std::move(clock);
  const int dim = run.dim;
  const std::size_t frames = run.frames();
  row.physics_steps = run.physics_steps;
  row.force_evals = run.work.force_evals;
  row.physics_t = run.physics_t;
  row.final_physics = run.final_physics;
  row.final_shown = run.final_shown;

  // The frames the per-frame figures cover: all but the last when it was shortened to
  // land on the horizon (a frame no display would show; its state at the horizon is
  // what final_shown_err and the frame-rate independence compare).
  std::size_t counted = frames;
  if (frames > 0) {
    const double full = config.clamp_s > 0.0 ? std::min(run.interval.back(), config.clamp_s) : run.interval.back();
    if (run.frame_time.back() < full * (1.0 - 1e-9)) counted = frames - 1;
  }
  row.frames = static_cast<long>(counted);

  count_steps(row, config, run, counted);

  // Frame-rate independence: the state at the horizon against the reference clock's.
  row.clock_dependence = row.physics_clock_dependence = nan;
  if (reference && !run.non_finite && !reference->non_finite) {
    row.clock_dependence = distance(run.final_shown.data(), reference->final_shown.data(), dim);
    row.physics_clock_dependence = distance(run.final_physics.data(), reference->final_physics.data(), dim);
  }

  auto no_errors = [&](std::string note) {
    row.shown_err_max = row.shown_err_rms = row.final_shown_err = row.judder = row.lag_s = nan;
    row.note = std::move(note);
    return row;
  };
  if (run.non_finite) {
    row.diverged = true;
    return no_errors(fmt::format("non-finite state at frame {} (display time {:g} s)", frames - 1,
                                 frames ? run.display_t.back() : 0.0));
  }
  if (!truth.trusted) return no_errors("no trusted truth: " + truth.note);
  check_truth_times(truth, run);

  // Shown error, and the lag that best explains it: shown(t) = exact(t - tau).
  double sum_sq = 0.0, lag_num = 0.0, lag_den = 0.0;
  for (std::size_t j = 0; j < counted; ++j) {
    const double* shown = run.shown.data() + j * dim;
    const double* exact = truth.y[j].data();
    const double e = distance(shown, exact, dim);
    row.shown_err_max = std::max(row.shown_err_max, e);
    sum_sq += e * e;
    for (int i = 0; i < dim; ++i) {
      lag_num += (shown[i] - exact[i]) * exact[dim + i];
      lag_den += exact[dim + i] * exact[dim + i];
    }
  }
  row.shown_err_rms = counted ? std::sqrt(sum_sq / static_cast<double>(counted)) : nan;
  row.final_shown_err = frames ? distance(run.shown.data() + (frames - 1) * dim, truth.y.back().data(), dim) : nan;
  row.lag_s = lag_den > 0.0 ? -lag_num / lag_den : nan;

  row.judder = judder(run, truth, counted);

  if (!(row.shown_err_max <= blowup_factor * truth.pos_scale)) {
    row.diverged = true;
    row.note = fmt::format("shown error {:.3g} exceeds {:g} times the amplitude", row.shown_err_max, blowup_factor);
  }
  return row;
}

loop_row run_loop_config(const problem_instance& problem, std::string_view method, const loop_config& config,
                         const loop_options& opts) {
  const loop_result run = problem.loop(method, config);  // throws std::invalid_argument for bad input
  const loop_config ref_config = reference_of(config, opts);
  const loop_result reference = same_run(ref_config, config) ? run : problem.loop(method, ref_config);
  const std::string clock = config.stalls() ? "stall" : config.jitter_seed ? "jitter" : "constant";
  return measure_loop(config, clock, run, loop_truth(problem, run), &reference);
}

loop_method run_loop_method(const problem_instance& problem, const method_info& method, const loop_options& opts) {
  loop_method out{method, {}};
  truth_cache truths(problem);
  const double horizon = problem.horizon();
  for (loop_design design : all_loop_designs) {
    // The variable design has no physics rate: it runs once per clock.
    const std::vector<double> rates =
        design == loop_design::variable ? std::vector<double>{opts.physics_hz.front()} : opts.physics_hz;
    for (double physics_hz : rates) {
      loop_config base;
      base.design = design;
      base.physics_hz = physics_hz;
      const auto clocks = study_clocks(base, horizon, opts);
      const loop_config ref_config = reference_of(clocks.front().config, opts);
      const loop_result reference = problem.loop(method.name, ref_config);
      for (const auto& [clock, config] : clocks) {
        const bool is_reference = same_run(config, ref_config);
        const loop_result run = is_reference ? reference : problem.loop(method.name, config);
        out.rows.push_back(measure_loop(config, clock, run, truths.at(run), &reference));
      }
    }
  }
  return out;
}

loop_study run_loop_study(const study& s, const loop_options& opts) {
  loop_study out;
  out.options = opts;
  const auto start = std::chrono::steady_clock::now();
  std::size_t configs = 0;
  for (const auto& ps : s.problems) {
    const std::string name(ps.problem->name());
    if (!contains(opts.problems, name)) continue;
    loop_problem lp;
    lp.name = name;
    lp.position_unit = ps.problem->position_unit();
    lp.horizon = ps.problem->horizon();
    for (const auto& m : ps.problem->methods()) {
      if (m.origin != method_origin::ours || m.kind != method_kind::fixed_step || !contains(opts.methods, m.name))
        continue;
      lp.methods.push_back(run_loop_method(*ps.problem, m, opts));
      configs += lp.methods.back().rows.size();
    }
    lp.truth_source = ps.problem->has_closed_form() ? "closed_form" : "references";
    if (!lp.methods.empty()) out.problems.push_back(std::move(lp));
  }
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (opts.progress && configs)
    std::fprintf(stderr, "loop study: %zu problem%s, %zu configurations in %.2f s\n", out.problems.size(),
                 out.problems.size() == 1 ? "" : "s", configs, out.wall_seconds);
  return out;
}

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

namespace {

void write_runs(H5::Group& g, const loop_method& m, double step_cost_ns, const std::string& source) {
  const auto& rows = m.rows;
  std::vector<loop_cost> costs;
  for (const auto& r : rows) costs.push_back(cost_verdict(r.config, step_cost_ns, source));
  auto col = [&](auto get) {
    using T = decltype(get(rows.front(), costs.front()));
    std::vector<T> v;
    for (std::size_t i = 0; i < rows.size(); ++i) v.push_back(get(rows[i], costs[i]));
    return v;
  };
  using R = const loop_row&;
  using C = const loop_cost&;
  auto i64 = [](auto x) { return static_cast<std::int64_t>(x); };
  auto i8 = [](bool x) { return static_cast<std::int8_t>(x); };
  auto variable = [](R r) { return r.config.design == loop_design::variable; };
  h5::table t;
  t.add("design", col([](R r, C) { return std::string(to_string(r.config.design)); }));
  t.add("clock", col([](R r, C) { return r.clock; }));
  t.add("display_hz", col([](R r, C) { return r.config.display_hz; }));
  t.add("physics_hz", col([&](R r, C) { return variable(r) ? nan : r.config.physics_hz; }));
  t.add("dt", col([&](R r, C) { return uses_accumulator(r.config.design) ? r.config.dt() : nan; }));
  t.add("substeps",
        col([&](R r, C) { return i64(r.config.design == loop_design::substeps ? r.config.substeps() : 0); }));
  t.add("clamp_s", col([](R r, C) { return r.config.clamp_s; }));
  t.add("jitter_seed", col([&](R r, C) { return r.config.jitter_seed ? i64(*r.config.jitter_seed) : i64(-1); }));
  t.add("stall_at_s", col([](R r, C) { return r.config.stall_at_s; }));
  t.add("frames", col([&](R r, C) { return i64(r.frames); }));
  t.add("physics_steps", col([&](R r, C) { return i64(r.physics_steps); }));
  t.add("force_evals", col([&](R r, C) { return i64(r.force_evals); }));
  t.add("shown_err_max", col([](R r, C) { return r.shown_err_max; }));
  t.add("shown_err_rms", col([](R r, C) { return r.shown_err_rms; }));
  t.add("final_shown_err", col([](R r, C) { return r.final_shown_err; }));
  t.add("clock_dependence", col([](R r, C) { return r.clock_dependence; }));
  t.add("physics_clock_dependence", col([](R r, C) { return r.physics_clock_dependence; }));
  t.add("judder", col([](R r, C) { return r.judder; }));
  t.add("lag_s", col([](R r, C) { return r.lag_s; }));
  t.add("lag_clock_s", col([](R r, C) { return r.lag_clock_s; }));
  t.add("steps_per_frame_mean", col([](R r, C) { return r.steps_per_frame_mean; }));
  t.add("steps_per_frame_max", col([&](R r, C) { return i64(r.steps_per_frame_max); }));
  t.add("stall_burst_steps", col([&](R r, C) { return i64(r.stall_burst_steps); }));
  t.add("clamp_hits", col([&](R r, C) { return i64(r.clamp_hits); }));
  t.add("alpha_min", col([](R r, C) { return r.alpha_min; }));
  t.add("alpha_max", col([](R r, C) { return r.alpha_max; }));
  t.add("physics_t", col([](R r, C) { return r.physics_t; }));
  t.add("diverged", col([&](R r, C) { return i8(r.diverged); }));
  t.add("note", col([](R r, C) { return r.note; }));
  t.add("step_cost_ns", col([](R, C c) { return c.step_cost_ns; }));
  t.add("frame_budget_ns", col([](R, C c) { return c.schedule.frame_budget_s * 1e9; }));
  t.add("worst_frame_work_ns", col([](R, C c) { return c.schedule.worst_work_s * 1e9; }));
  t.add("late_frames", col([&](R, C c) { return i64(c.schedule.late_frames); }));
  t.add("physics_load", col([](R, C c) { return c.schedule.load; }));
  t.add("outcome", col([](R, C c) { return std::string(to_string(c.schedule.outcome)); }));
  t.add("outcome_without_clamp", col([](R, C c) { return std::string(to_string(c.without_clamp)); }));
  t.add("clamp_prevented_spiral", col([&](R, C c) { return i8(c.clamp_prevented_spiral); }));
  t.write(g, "runs", schema::find("loop_runs"));
  std::vector<std::vector<double>> finals;
  for (const auto& r : rows) finals.push_back(r.final_physics);
  h5::dataset(g, "final_physics_state", finals);
}

void write_cheapest(H5::Group& g, const loop_method& m, const loop_options& opts) {
  const auto rows = cheapest_designs(m, opts);
  h5::table t;
  auto col = [&](auto get) {
    using T = decltype(get(rows.front()));
    std::vector<T> v;
    for (const auto& r : rows) v.push_back(get(r));
    return v;
  };
  t.add("display_hz", col([](const loop_cheapest& c) { return c.display_hz; }));
  t.add("target", col([](const loop_cheapest& c) { return c.target; }));
  t.add("found", col([](const loop_cheapest& c) { return static_cast<std::int8_t>(c.found); }));
  t.add("design", col([](const loop_cheapest& c) { return c.design; }));
  t.add("physics_hz", col([](const loop_cheapest& c) { return c.physics_hz; }));
  t.add("steps_per_frame_mean", col([](const loop_cheapest& c) { return c.steps_per_frame_mean; }));
  t.add("shown_err_max", col([](const loop_cheapest& c) { return c.shown_err_max; }));
  t.write(g, "cheapest", schema::find("loop_cheapest"));
}

}  // namespace

void write_loop(H5::Group& root, const study& s) {
  const loop_study& ls = s.results.get<loop_study>();
  if (ls.problems.empty()) return;
  const loop_options& o = ls.options;
  H5::Group top = root.createGroup("loop");
  std::string designs;
  for (loop_design d : all_loop_designs) designs += (designs.empty() ? "" : ",") + std::string(to_string(d));
  h5::attr(top, "designs", designs);
  h5::attr(top, "display_hz", o.display_hz);
  h5::attr(top, "physics_hz", o.physics_hz);
  h5::attr(top, "reference_display_hz", o.reference_display_hz);
  h5::attr(top, "clamp_s", o.clamp_s);
  h5::attr(top, "stall_s", o.stall_s);
  h5::attr(top, "stall_at_fraction", o.stall_at_fraction);
  h5::attr(top, "jitter", o.jitter);
  h5::attr(top, "jitter_seed", static_cast<long>(o.jitter_seed));
  h5::attr(
      top, "jitter_distribution",
      "interval = (1 + jitter (2u - 1)) / display_hz, u = (x >> 11) 2^-53, x the outputs of std::mt19937_64(seed)");
  h5::attr(top, "accumulator_slack", accumulator_slack);
  h5::attr(top, "target", o.target);
  h5::attr(top, "stated_step_cost_ns", o.stated_step_cost_ns);
  h5::attr(top, "spiral_factor", spiral_factor);
  h5::attr(top, "settle_frames", settle_frames);
  h5::attr(top, "wall_seconds", ls.wall_seconds);
  for (const auto& lp : ls.problems) {
    H5::Group pg = top.createGroup(lp.name);
    h5::attr(pg, "position_unit", lp.position_unit);
    h5::attr(pg, "horizon", lp.horizon);
    h5::attr(pg, "truth_source", lp.truth_source);
    const problem_study* ps = nullptr;
    for (const auto& p : s.problems)
      if (p.problem->name() == lp.name) ps = &p;
    for (const auto& m : lp.methods) {
      H5::Group mg = pg.createGroup(m.info.name);
      const double measured = ps && s.timed ? measured_step_cost_ns(*ps, m.info.name) : nan;
      const bool is_measured = std::isfinite(measured) && measured > 0.0;
      const double cost = is_measured ? measured : o.stated_step_cost_ns;
      const std::string source = is_measured ? "measured" : "stated";
      h5::attr(mg, "step_cost_ns", cost);
      h5::attr(mg, "step_cost_source", source);
      write_runs(mg, m, cost, source);
      write_cheapest(mg, m, o);
    }
  }
}

}  // namespace stepbench

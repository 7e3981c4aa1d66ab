#include "run/loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>

#include "core/contains.hpp"
#include "core/measure.hpp"
#include "core/number.hpp"

namespace stepbench {
namespace {

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

// The exact state at the frames' display times: the closed form, or the references.
truth_table loop_truth(const problem_instance& problem, const loop_result& run) {
  truth_options opts;
  opts.run_references = !problem.has_closed_form();
  return build_truth(problem, run.display_t, opts);
}

// A simulated run against the truth at its display times; `reference` is the same
// configuration on the reference clock.
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
    row.clock_dependence = norm(run.final_shown, 0, dim, reference->final_shown);
    row.physics_clock_dependence = norm(run.final_physics, 0, dim, reference->final_physics);
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
  if (truth.times != run.display_t) throw std::logic_error("measure_loop: the truth's times are not the run's frames");

  // Shown error, and the lag that best explains it: shown(t) = exact(t - tau).
  double sum_sq = 0.0, lag_num = 0.0, lag_den = 0.0;
  for (std::size_t j = 0; j < counted; ++j) {
    const auto shown = std::span(run.shown).subspan(j * dim);
    const auto& exact = truth.y[j];
    const double e = norm(shown, 0, dim, exact);
    row.shown_err_max = std::max(row.shown_err_max, e);
    sum_sq += e * e;
    for (int i = 0; i < dim; ++i) {
      lag_num += (shown[i] - exact[i]) * exact[dim + i];
      lag_den += exact[dim + i] * exact[dim + i];
    }
  }
  row.shown_err_rms = counted ? std::sqrt(sum_sq / static_cast<double>(counted)) : nan;
  row.final_shown_err = frames ? norm(std::span(run.shown).subspan((frames - 1) * dim), 0, dim, truth.y.back()) : nan;
  row.lag_s = lag_den > 0.0 ? -lag_num / lag_den : nan;

  row.judder = judder(run, truth, counted);

  if (!(row.shown_err_max <= blowup_factor * truth.pos_scale)) {
    row.diverged = true;
    row.note = fmt::format("shown error {:.3g} exceeds {:g} times the amplitude", row.shown_err_max, blowup_factor);
  }
  return row;
}

}  // namespace

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
  // The truths by their display times: every design and physics rate on one clock shows
  // its frames at the same times, so each clock's truth is built once.
  std::vector<truth_table> truths;
  const auto truth_at = [&](const loop_result& run) -> const truth_table& {
    for (const auto& t : truths)
      if (t.times == run.display_t) return t;
    return truths.emplace_back(loop_truth(problem, run));
  };
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
        out.rows.push_back(measure_loop(config, clock, run, truth_at(run), &reference));
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
      if (!offered_as_ours(m.origin) || m.kind != method_kind::fixed_step || !contains(opts.methods, m.name)) continue;
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

}  // namespace stepbench

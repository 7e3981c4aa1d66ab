#include "run/sweep.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/contains.hpp"
#include "core/drive.hpp"
#include "core/measure.hpp"
#include "run/balanced_share.hpp"
#include "run/machine.hpp"
#include "run/scan.hpp"

namespace stepbench {

std::unique_ptr<problem_instance> configured_problem(const std::string& name, const sweep_options& opts) {
  auto p = make_problem(name);
  if (auto it = opts.overrides.find(name); it != opts.overrides.end())
    for (const auto& [param, value] : it->second) p->set(param, value);
  if (auto err = p->validate(); !err.empty()) throw std::invalid_argument(fmt::format("problem {}: {}", name, err));
  return p;
}

void validate(const sweep_options& opts) {
  if (opts.levels < 2 || opts.levels > 20) throw std::invalid_argument("levels must be between 2 and 20");
  if (opts.max_levels < opts.levels || opts.max_levels > 24)
    throw std::invalid_argument(fmt::format("max levels must be between levels ({}) and 24", opts.levels));
  if (!(opts.round_off_fall > 1.0)) throw std::invalid_argument("the round-off fall must be > 1");
  if (opts.base_steps < 1 || opts.sample_count < 1 || opts.base_steps % opts.sample_count != 0)
    throw std::invalid_argument("base_steps must be a positive multiple of sample_count");
  if (!(opts.tol.rtol > 0.0 && opts.tol.atol > 0.0)) throw std::invalid_argument("reference tolerances must be > 0");
  for (double tol : opts.tolerances)
    if (!(tol > 0.0 && tol < 1.0)) throw std::invalid_argument(fmt::format("tolerance {:g} is not in (0, 1)", tol));
  // The parts' own method and problem lists name registry entries: a renamed method or
  // problem fails here, at the start, instead of dropping out of a part unseen.
  for (const auto* names : {&opts.methods, &opts.loop.methods, &opts.substeps.explicit_methods,
                            &opts.substeps.implicit_methods, &opts.challenge.competitors, &opts.energy.methods})
    for (const auto& name : *names) find_method(name);
  for (const auto* names : {&opts.loop.problems, &opts.substeps.problems})
    for (const auto& name : *names) make_problem(name);
  for (const auto& scene : opts.energy.scenes) make_problem(scene.problem);
  // The frame-rate study's truth is built at the fastest rate's frame ends and read at
  // every rate's: each rate must divide the fastest.
  if (!opts.frame_rates.hz.empty()) {
    const double fastest = *std::max_element(opts.frame_rates.hz.begin(), opts.frame_rates.hz.end());
    for (double hz : opts.frame_rates.hz) {
      if (!(hz > 0.0 && std::isfinite(hz)))
        throw std::invalid_argument(fmt::format("frame rate {:g} Hz is not a positive, finite rate", hz));
      if (std::abs(fastest / hz - std::round(fastest / hz)) > 1e-9)
        throw std::invalid_argument(
            fmt::format("frame rate {:g} Hz does not divide the fastest, {:g} Hz", hz, fastest));
    }
  }
  if (opts.shard_count < 1 || opts.shard_index < 0 || opts.shard_index >= opts.shard_count)
    throw std::invalid_argument(fmt::format("shard {} of {} does not exist", opts.shard_index + 1, opts.shard_count));
  for (const auto* names : {&opts.problems, &opts.methods})
    for (size_t i = 0; i < names->size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if ((*names)[i] == (*names)[j]) throw std::invalid_argument(fmt::format("'{}' is named twice", (*names)[i]));
  // A bound on the work: the finest level's steps (run has the same kind of bound; the
  // levels beyond `levels` are bounded by the work budget as well).
  const double finest = static_cast<double>(opts.base_steps) * std::ldexp(1.0, opts.max_levels - 1);
  if (finest > 1e8)
    throw std::invalid_argument(fmt::format(
        "the ladder's finest level would take {:.3g} steps (base_steps 2^(max_levels-1)); the limit is 1e8", finest));
  for (const auto& [name, params] : opts.overrides) {
    auto problem = make_problem(name);                                     // throws, naming an unknown problem
    for (const auto& [param, value] : params) problem->set(param, value);  // throws for an unknown parameter
    if (!opts.problems.empty() && !contains(opts.problems, name))
      throw std::invalid_argument(fmt::format("--set names problem {}, which is not in the sweep", name));
  }
  const auto names = selected_problems(opts);
  for (const auto& name : names) configured_problem(name, opts);
  for (const auto& sc : opts.scans.value_or(default_scans())) validate(sc);
  // A method named explicitly must run on at least one selected problem.
  for (const auto& m : opts.methods) {
    bool runs = false;
    for (const auto& name : names)
      for (const auto& info : make_problem(name)->methods()) runs = runs || info.name == m;
    if (!runs) throw std::invalid_argument(fmt::format("method {} runs on none of the selected problems", m));
  }
}

std::vector<double> param_ladder(const method_info& m, double horizon, const sweep_options& opts) {
  if (m.kind != method_kind::fixed_step) return opts.tolerances;
  std::vector<double> out;
  for (int k = 0; k < opts.max_levels; ++k)
    out.push_back(horizon / (static_cast<double>(opts.base_steps) * std::ldexp(1.0, k)));
  return out;
}

void fit_rows(method_study& ms, double pos_scale) {
  fit_input fit;
  fit.scale = pos_scale;
  for (const auto& row : ms.rows) {
    fit.dt.push_back(row.param);
    fit.error.push_back(row.metrics.err_pos_max);
    fit.steps.push_back(row.steps);
    fit.incomplete.push_back(!row.metrics.completed());
  }
  ms.fit = fit_order(fit);
  ms.declared_order_holds =
      ms.info.kind == method_kind::fixed_step ? declared_order_holds(ms.info.declared_order, ms.fit) : -1;
}

namespace {

// Why a fixed-step ladder stops after its rows, or "" while it goes on. The first
// `levels` rows always run (a level over the work budget is recorded as skipped); beyond
// them the ladder halves dt while the last level completed, the next fits the work
// budget, and the error still falls: it stops once the error fell by less than
// `round_off_fall` over the last level, at round-off (within 100 times the typical
// round-off eps sqrt(n) scale, the fit's own cut, core/convergence_fit.hpp), or else after
// two such levels in a row (an error floor above round-off, as a contact's timing gives).
// The ladder's length is checked last: a last level that also reached round-off, an error
// floor or the budget is labelled by that, which says more about the method.
std::string fixed_ladder_end(const std::vector<method_row>& rows, double dim, double scale, const sweep_options& opts) {
  const int k = static_cast<int>(rows.size());
  if (k < opts.levels) return "";
  const auto or_ladder_end = [&](std::string why) {
    if (!why.empty() || k < opts.max_levels) return why;
    return fmt::format("the ladder's last level ({}){}", opts.max_levels,
                       opts.max_levels == opts.levels ? "" : ", before round-off or the work budget");
  };
  const auto& last = rows.back();
  if (last.metrics.skipped) return "the work budget (the finer levels were skipped)";
  if (!last.metrics.completed()) return "divergence at the finest level";
  const double err = last.metrics.err_pos_max;
  if (!(err > 0.0)) return "an error of 0 (exact for the problem)";
  // The fall over the level ending at row j (infinite after a level that did not complete).
  const auto fall = [&](std::size_t j) {
    const auto& before = rows[j - 1].metrics;
    return before.completed() ? before.err_pos_max / rows[j].metrics.err_pos_max
                              : std::numeric_limits<double>::infinity();
  };
  const std::size_t n = rows.size();
  const double next_work = 2.0 * static_cast<double>(last.work.force_evals) * dim;
  const std::string budget =
      next_work > opts.limits.work_budget
          ? fmt::format("the work budget: the next level would take {:.3g} coordinate force evaluations, over {:.3g}",
                        next_work, opts.limits.work_budget)
          : "";
  if (fall(n - 1) > opts.round_off_fall) return or_ladder_end(budget);
  if (err <= 100.0 * roundoff_noise(last.steps, scale))
    return fmt::format(
        "round-off: the error {:.3g} fell {:.3g}x over the last level, within 100 eps sqrt(n) of round-off", err,
        fall(n - 1));
  if (n >= 3 && rows[n - 2].metrics.completed() && rows[n - 2].metrics.err_pos_max > 0.0 &&
      fall(n - 2) <= opts.round_off_fall)
    return fmt::format(
        "an error floor: the error {:.3g} fell {:.3g}x and {:.3g}x over the last two levels, above the eps sqrt(n) "
        "round-off estimate",
        err, fall(n - 2), fall(n - 1));
  return or_ladder_end(budget);
}

}  // namespace

method_study run_method(const problem_study& ps, const method_info& m, const sweep_options& opts) {
  method_study ms;
  ms.info = m;
  const double dim = ps.problem->dim();
  const bool fixed = m.kind == method_kind::fixed_step;
  for (double param : param_ladder(m, ps.horizon, opts)) {
    if (fixed) {
      if (ms.ladder_end = fixed_ladder_end(ms.rows, dim, ps.truth.pos_scale, opts); !ms.ladder_end.empty()) break;
      // A level within `levels` whose work (twice the previous level's force evaluations,
      // times the coordinates) would exceed the budget is skipped, with the reason.
      if (!ms.rows.empty() && ms.rows.back().work.force_evals > 0 &&
          2.0 * static_cast<double>(ms.rows.back().work.force_evals) * dim > opts.limits.work_budget) {
        ms.rows.push_back(skipped_row(
            param,
            fmt::format("skipped: about {:.3g} force evaluations x {:g} coordinates exceed the work budget of {:.3g}",
                        2.0 * static_cast<double>(ms.rows.back().work.force_evals), dim, opts.limits.work_budget)));
        continue;
      }
    }
    const run_result run = ps.problem->run(m.name, param, ps.horizon, ps.truth.times, opts.limits);
    ms.rows.push_back({param, run.steps, run.rejected_steps, run.work, measure(*ps.problem, run, ps.truth), {}});
  }
  if (fixed && ms.ladder_end.empty()) ms.ladder_end = fixed_ladder_end(ms.rows, dim, ps.truth.pos_scale, opts);
  if (!fixed && !opts.tolerances.empty())
    ms.ladder_end = fmt::format("the tolerance ladder's end ({:g})", opts.tolerances.back());
  fit_rows(ms, ps.truth.pos_scale);
  return ms;
}

std::vector<std::string> selected_problems(const sweep_options& opts) {
  return opts.problems.empty() ? problem_names() : opts.problems;
}

double sweep_cost(const std::string& problem, const sweep_options& opts) {
  const auto p = configured_problem(problem, opts);
  std::size_t methods = 0;
  for (const auto& m : p->methods()) methods += opts.methods.empty() || contains(opts.methods, m.name);
  const double ladder = static_cast<double>(opts.base_steps) * (std::ldexp(1.0, opts.levels) - 1.0);
  // The references run on every problem (checked against a closed form where there is one).
  return static_cast<double>(p->dim()) * ladder * static_cast<double>(methods) +
         reference_work_in_evaluations * predicted_reference_work(*p, p->horizon());
}

std::vector<std::string> sweep_shard(const sweep_options& opts, int k, int n) {
  if (n < 1 || k < 0 || k >= n) throw std::invalid_argument(fmt::format("shard {} of {} does not exist", k + 1, n));
  const auto names = selected_problems(opts);
  if (n == 1) return names;
  std::vector<double> cost;
  for (const auto& name : names) cost.push_back(sweep_cost(name, opts));
  const auto mine = balanced_share(cost, k, n);
  std::vector<std::string> out;
  for (std::size_t i : mine) out.push_back(names[i]);
  return out;
}

std::vector<std::string> shard_problems(const sweep_options& opts) {
  return sweep_shard(opts, opts.shard_index, opts.shard_count);
}

int sweep_jobs(const sweep_options& opts, std::size_t problems) {
  const int cores = std::max(1, core_count());
  const int jobs = opts.jobs > 0 ? opts.jobs : cores;
  return static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(jobs, problems)));
}

}  // namespace stepbench

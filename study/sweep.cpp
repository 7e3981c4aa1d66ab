#include "core/sweep.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "core/drive.hpp"

namespace stepbench {
namespace {

std::vector<std::string> selected(const std::vector<std::string>& chosen, std::vector<std::string> all) {
  return chosen.empty() ? all : chosen;
}

std::unique_ptr<problem_instance> configured_problem(const std::string& name, const sweep_options& opts) {
  auto p = make_problem(name);
  if (auto it = opts.overrides.find(name); it != opts.overrides.end())
    for (const auto& [param, value] : it->second) p->set(param, value);
  if (auto err = p->validate(); !err.empty())
    throw std::invalid_argument(fmt::format("problem {}: {}", name, err));
  return p;
}

}  // namespace

void validate(const sweep_options& opts) {
  if (opts.levels < 2 || opts.levels > 20) throw std::invalid_argument("levels must be between 2 and 20");
  if (opts.base_steps < 1 || opts.sample_count < 1 || opts.base_steps % opts.sample_count != 0)
    throw std::invalid_argument("base_steps must be a positive multiple of sample_count");
  if (!(opts.tol.rtol > 0.0 && opts.tol.atol > 0.0)) throw std::invalid_argument("reference tolerances must be > 0");
  for (const auto& name : selected(opts.integrators, {})) find_integrator(name);
  for (const auto* names : {&opts.problems, &opts.integrators})
    for (size_t i = 0; i < names->size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if ((*names)[i] == (*names)[j]) throw std::invalid_argument(fmt::format("'{}' is named twice", (*names)[i]));
  // A bound on the work: the finest level's steps (run has the same kind of bound).
  const double finest = static_cast<double>(opts.base_steps) * std::ldexp(1.0, opts.levels - 1);
  if (finest > 1e8)
    throw std::invalid_argument(fmt::format(
        "the ladder's finest level would take {:.3g} steps (base_steps 2^(levels-1)); the limit is 1e8", finest));
  for (const auto& [name, params] : opts.overrides) {
    auto problem = make_problem(name);  // throws, naming an unknown problem
    for (const auto& [param, value] : params) problem->set(param, value);  // throws for an unknown parameter
    bool chosen = opts.problems.empty();
    for (const auto& p : opts.problems) chosen = chosen || p == name;
    if (!chosen) throw std::invalid_argument(fmt::format("--set names problem {}, which is not in the sweep", name));
  }
  for (const auto& name : selected(opts.problems, problem_names())) configured_problem(name, opts);
}

std::vector<double> dt_ladder(double horizon, const sweep_options& opts) {
  std::vector<double> out;
  for (int k = 0; k < opts.levels; ++k) out.push_back(horizon / (static_cast<double>(opts.base_steps) * std::ldexp(1.0, k)));
  return out;
}

study run_sweep(const sweep_options& opts) {
  validate(opts);
  const auto start = std::chrono::steady_clock::now();
  study out;
  out.options = opts;
  std::vector<std::string> integrator_names;
  for (const auto& i : integrators()) integrator_names.push_back(i.name);
  integrator_names = selected(opts.integrators, integrator_names);

  for (const auto& name : selected(opts.problems, problem_names())) {
    problem_study ps;
    ps.problem = configured_problem(name, opts);
    ps.horizon = ps.problem->horizon();
    std::vector<double> times;
    for (int j = 1; j <= opts.sample_count; ++j)
      times.push_back(j == opts.sample_count ? ps.horizon : ps.horizon * j / opts.sample_count);
    ps.truth = build_truth(*ps.problem, times, {.tol = opts.tol});

    const auto ladder = dt_ladder(ps.horizon, opts);
    for (const auto& iname : integrator_names) {
      integrator_study is;
      is.info = find_integrator(iname);
      fit_input fit;
      fit.scale = ps.truth.pos_scale;
      for (double dt : ladder) {
        const auto steps = sample_steps(ps.horizon, dt, opts.sample_count);
        const run_result run = ps.problem->run(iname, dt, ps.horizon, steps);
        convergence_row row{dt, run.steps, run.force_evals, measure(*ps.problem, run, ps.truth), {}};
        fit.dt.push_back(dt);
        fit.error.push_back(row.metrics.err_pos_max);
        fit.steps.push_back(run.steps_planned);
        fit.diverged.push_back(row.metrics.diverged);
        is.rows.push_back(std::move(row));
      }
      is.fit = fit_order(fit);
      ps.integrators.push_back(std::move(is));
    }
    out.problems.push_back(std::move(ps));
  }
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace stepbench

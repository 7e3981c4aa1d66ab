// The sweep (/problems): every selected method on every problem of this run, over its
// ladder, measured against the truth; the rows every other part reads.
#include "run/sweep.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>

#include "core/contains.hpp"
#include "parts/part.hpp"
#include "registry/plugins.hpp"
#include "run/machine.hpp"
#include "store/study_file.hpp"

namespace stepbench {
namespace {

// The plugins loaded, a line each (none: no line, so a study without them describes
// itself as before): merge joins only shards that ran the same builds of them.
std::string plugins_described() {
  std::string out;
  for (const auto& p : loaded_plugins())
    out += fmt::format("\nplugin: {} fnv1a_64 {} abi {}", p.path, p.fnv1a_64, p.abi_version);
  return out;
}

std::string describe(const sweep_options& o) {
  std::vector<std::string> overrides;
  for (const auto& [problem, params] : o.overrides)
    for (const auto& [name, value] : params) overrides.push_back(fmt::format("{}.{}={}", problem, name, value));
  return fmt::format(
      "selection: {}\nmethods: {}\noverrides: {}\nlevels: {}\nmax_levels: {}\nround_off_fall: {}\n"
      "base_steps: {}\nsample_count: {}\ntolerances: {}\nreference tolerances: rtol {} atol {}\n"
      "work budget: {} (adaptive steps {}){}",
      list_or_all(selected_problems(o)), list_or_all(o.methods),
      overrides.empty() ? "none" : fmt::format("{}", fmt::join(overrides, ",")), o.levels, o.max_levels,
      o.round_off_fall, o.base_steps, o.sample_count, fmt::join(o.tolerances, ","), o.tol.rtol, o.tol.atol,
      o.limits.work_budget, o.limits.max_steps, plugins_described());
}

// One problem: its truth and every selected method on its ladder.
problem_study sweep_problem(const std::string& name, const sweep_options& opts, const part_context& ctx) {
  const auto t0 = std::chrono::steady_clock::now();
  problem_study ps;
  ps.problem = configured_problem(name, opts);
  ps.name = ps.problem->name();
  ps.unit = ps.problem->position_unit();
  for (const auto& p : ps.problem->params()) ps.params[p.name] = p.value;
  ps.horizon = ps.problem->horizon();
  ps.dim = ps.problem->dim();
  ps.truth = build_truth(*ps.problem, sample_times(ps.horizon, opts.sample_count), {.tol = opts.tol});
  for (const auto& r : ps.truth.references)
    if (r.status != "ok" && r.status != "unsupported")
      ctx.say(fmt::format("warning: {}: reference {} {}: {}", name, r.source, r.status, r.reason));
  if (!ps.truth.trusted)
    ctx.say(fmt::format("warning: {}: no trusted truth ({}); its errors are recorded as NaN", name, ps.truth.note));
  for (const auto& m : ps.problem->methods())
    if (opts.methods.empty() || contains(opts.methods, m.name)) ps.methods.push_back(run_method(ps, m, opts));
  if (ctx.progress)
    ctx.say(fmt::format("swept {:<22} {:3} methods in {:.2f} s", name, ps.methods.size(),
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  return ps;
}

// The problems run on `jobs` threads (each problem's runs own their state: the references
// and peers make their solver objects per run), each into its own slot, so the study is
// the same as on one thread.
void run(study& s, const part_context& ctx) {
  std::vector<problem_study> swept(ctx.problems.size());
  parallel_indices(
      ctx.problems.size(), sweep_jobs(s.options, ctx.problems.size()),
      [&](std::size_t i) { swept[i] = sweep_problem(ctx.problems[i], s.options, ctx); }, ctx.step_done);
  for (auto& ps : swept) s.problems.push_back(std::move(ps));
}

}  // namespace

extern const study_part sweep_part{
    .name = "sweep",
    .summary = "every method on every problem over its dt or tolerance ladder, measured against the truth",
    .group = "problems",
    .has_timed_cases = true,
    .progress_per_problem = true,
    .describe = describe,
    .run = run,
    .write = write_problems,
    .read = read_problems,
};

}  // namespace stepbench

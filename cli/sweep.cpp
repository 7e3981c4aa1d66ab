// `stepbench sweep`: the accuracy study (every method on every problem over its ladder,
// untimed) into an HDF5 study file.
#include "run/sweep.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <ctime>
#include <filesystem>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "judge/outcome.hpp"
#include "parts/part.hpp"
#include "parts/study.hpp"
#include "store/study_file.hpp"

namespace stepbench::cli {
namespace {

struct sweep_args {
  sweep_options opts;
  std::vector<std::string> sets;
  std::string shard, out;  // shard: K/N; out: new_study_path() when not given
  std::vector<std::string> parts;
  bool quiet = false, quick = false, strict = false;
};

std::string observed(const method_study& ms) {
  if (ms.fit.state == fit_result::status::fitted) return fmt::format("{:.3f}", ms.fit.order);
  return ms.fit.state == fit_result::status::exact ? "exact" : "n/a";
}

// Without --out, a new file that overwrites no study (results/study.h5 is the main study,
// hours of timing): results/sweep-<UTC date and time>.h5, with -2, -3 ... while that exists.
std::string new_study_path() {
  const std::string stamp = fmt::format("{:%Y%m%d-%H%M%S}", fmt::gmtime(std::time(nullptr)));
  for (int k = 1;; ++k) {
    std::string path = fmt::format("results/sweep-{}{}.h5", stamp, k > 1 ? fmt::format("-{}", k) : "");
    if (!std::filesystem::exists(path)) return path;
  }
}

int run_sweep_command(sweep_args a) {
  for (const auto& s : a.sets) add_override(a.opts.overrides, s, a.opts.problems);
  if (a.quick) find_preset("quick").apply(a.opts);
  if (!a.parts.empty()) a.opts.parts = a.parts;
  if (!a.shard.empty()) parse_shard(a.shard, a.opts.shard_index, a.opts.shard_count);
  a.opts.progress = !a.quiet;
  validate(a.opts);
  selected_parts(a.opts);
  if (a.out.empty()) a.out = new_study_path();
  check_writable(a.out);  // before the work, so a bad path costs nothing
  const study s = run_sweep(a.opts);
  write_study(s, a.out);
  if (!a.quiet) {
    fmt::print("{:<22} {:<24} {:<10} {:>8} {:>9}  {}\n", "problem", "method", "kind", "declared", "observed",
               "fit levels");
    for (const auto& ps : s.problems)
      for (const auto& ms : ps.methods) {
        std::size_t bad = 0;
        for (const auto& r : ms.rows) bad += r.metrics.diverged || r.metrics.failed;
        fmt::print("{:<22} {:<24} {:<10} {:>8} {:>9}  {}{}\n", ps.problem->name(), ms.info.name,
                   to_string(ms.info.kind),
                   std::isfinite(ms.info.declared_order) ? fmt::format("{:g}", ms.info.declared_order) : "-",
                   ms.info.kind == method_kind::fixed_step ? observed(ms) : "-", fmt::join(ms.fit.levels, ","),
                   bad ? fmt::format("  ({} of {} rows diverged or failed)", bad, ms.rows.size()) : "");
      }
    for (const auto& ps : s.problems)
      for (const auto& r : ps.truth.references)
        fmt::print("reference {:<12} on {:<22} {:<9} vs {:<12} pos {:.2e} vel {:.2e}  ({} steps, {} f evals)\n",
                   r.source, ps.problem->name(), r.status, r.compared_with.empty() ? "-" : r.compared_with,
                   r.vs.pos_rel, r.vs.vel_rel, r.solution.stats.steps, r.solution.stats.rhs_evals_counted);
  }
  std::fflush(stdout);
  fmt::print(stderr, "wrote {} ({}{}, {}) in {:.2f} s\n", a.out, count_of(s.problems.size(), "problem"),
             a.opts.shard_count > 1 ? fmt::format(": shard {} of {}", a.opts.shard_index + 1, a.opts.shard_count) : "",
             count_of(a.opts.levels, "level"), s.wall_seconds);
  return report_study_outcome(s, "stepbench", a.strict);
}

}  // namespace

command add_sweep(CLI::App& app) {
  auto a = std::make_shared<sweep_args>();
  auto* sub = app.add_subcommand("sweep", "accuracy study of every (problem, method) into an HDF5 study file");
  sub->add_option("--problem", a->opts.problems, "restrict to these problems (repeatable)");
  sub->add_option("--integrator,--method", a->opts.methods, "restrict to these methods (repeatable)");
  sub->add_option("--levels", a->opts.levels, "timesteps every fixed-step method runs in the halving ladder")
      ->capture_default_str();
  sub->add_option("--jobs", a->opts.jobs, "threads the problems are swept on (0: one a core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--max-levels", a->opts.max_levels,
                  "levels a fixed-step ladder may reach while its error still falls and the work budget allows")
      ->capture_default_str();
  sub->add_option("--base-steps", a->opts.base_steps, "steps at the coarsest level")->capture_default_str();
  sub->add_option("--set", a->sets,
                  "override a parameter, problem.name=value, or name=value with one --problem (repeatable)");
  sub->add_option("--shard", a->shard,
                  "K/N: sweep shard K of N, a deterministic share of the selected problems balanced by their counted "
                  "cost, with every part of the study that belongs to them (`stepbench merge` joins the shards)");
  sub->add_option("--out", a->out,
                  "study file to write (default: a new results/sweep-<UTC date-time>.h5, never an existing file; "
                  "the summary line says where)");
  sub->add_flag("--quick", a->quick,
                "the quick preset (the CI study): 8 levels (no more), every other tolerance, the quick scan, every "
                "part but the challenge");
  sub->add_option("--parts", a->parts,
                  "run only these parts of the study, in the study's order (comma-separated or repeated; "
                  "`stepbench list` names them)")
      ->delimiter(',');
  sub->add_flag("--quiet", a->quiet, "print only the summary line");
  sub->add_flag("--strict", a->strict, "exit 3 when a method failed on some case");
  sub->footer(
      "exit codes: 0 written whole (a method that failed on a case is a finding, recorded with its reason and "
      "summed up on stderr, one line per method and problem); 1 a file error, or a problem without a trusted "
      "truth (the file is still written); 2 bad usage; 3 with --strict, written but some case failed\n");
  return {sub, [a] { return run_sweep_command(*a); }};
}

}  // namespace stepbench::cli

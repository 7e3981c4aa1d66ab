// A scene's whole range (/scan): the default scans of this run's problems.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>

#include "core/contains.hpp"
#include "judge/scan.hpp"
#include "parts/part.hpp"
#include "render/scan.hpp"
#include "run/scan.hpp"
#include "run/sweep.hpp"
#include "store/scan.hpp"

namespace stepbench {
namespace {

std::string describe(const sweep_options& o) {
  std::vector<std::string> scans;
  for (const auto& sc : o.scans.value_or(default_scans())) {
    std::vector<std::string> axes;
    for (const auto& a : sc.axes)
      axes.push_back(fmt::format("{}={}:{}:{}{}", a.param, a.lo, a.hi, a.count, a.log ? ":log" : ""));
    scans.push_back(fmt::format("{} {} at {} Hz, substeps {}, methods {}, tol {}",
                                sc.name.empty() ? sc.problem : sc.name, fmt::join(axes, " x "), fmt::join(sc.hz, ","),
                                fmt::join(sc.substeps, ","), list_or_all(sc.methods), sc.tol));
  }
  return fmt::format("scans: {}", scans.empty() ? "none" : fmt::format("{}", fmt::join(scans, "; ")));
}

// The scans of this run's problems, with the sweep's methods where it names them.
void run(study& s, const part_context& ctx) {
  const sweep_options& opts = s.options;
  std::vector<scan_result> out;
  for (scan_options sc : opts.scans.value_or(default_scans())) {
    if (!contains(ctx.problems, sc.problem)) continue;
    if (!opts.methods.empty()) {
      sc.methods.clear();
      for (const auto& m : make_problem(sc.problem)->methods())
        if (m.kind == method_kind::fixed_step && contains(opts.methods, m.name)) sc.methods.push_back(m.name);
      if (sc.methods.empty()) continue;
    }
    sc.ref_tol = opts.tol;
    // The sweep's limits, but the tighter work budget: a default scan may set its own
    // (the rope's, study/scan.cpp default_scans), and a sweep's --work-budget still binds.
    const double scan_budget = sc.limits.work_budget;
    sc.limits = opts.limits;
    sc.limits.work_budget = std::min(scan_budget, opts.limits.work_budget);
    sc.jobs = opts.jobs;
    if (auto it = opts.overrides.find(sc.problem); it != opts.overrides.end())
      for (const auto& [name, value] : it->second)
        if (std::none_of(sc.axes.begin(), sc.axes.end(), [&](const scan_axis& a) { return a.param == name; }))
          sc.fixed[name] = value;
    const auto t0 = std::chrono::steady_clock::now();
    out.push_back(run_scan(sc));
    if (ctx.progress)
      ctx.say(fmt::format("scan    {:<22} {} points in {:.2f} s", sc.problem, out.back().points.size(),
                          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  }
  if (!out.empty()) s.results.put(std::move(out));
}

}  // namespace

extern const study_part scans_part{
    .name = "scans",
    .summary =
        "over a scene's parameter range: the cheapest method and substeps within tolerance, and where each breaks",
    .group = "scan",
    .merge = merge_rule::in_one_shard,
    .describe = describe,
    .run = run,
    .judge =
        [](study& s) {
          if (auto* scans = s.results.find<std::vector<scan_result>>())
            for (auto& sc : *scans) sc.range_answer = format_scan_answer(answer_scan(sc, sc.options.tol));
        },
    .write = write_result<std::vector<scan_result>, write_scans>,
};

}  // namespace stepbench

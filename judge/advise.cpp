#include "judge/advise.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <ranges>
#include <set>
#include <stdexcept>

#include "judge/rows.hpp"
#include "judge/scan.hpp"
#include "judge/verdict.hpp"

namespace stepbench {
advice advise(const study& study, const std::string& problem, const std::string& metric, double tol) {
  if (!is_error_metric(metric))
    throw std::invalid_argument(fmt::format("unknown metric '{}' (known: {})", metric, fmt::join(error_metrics, ", ")));
  if (!(tol > 0.0) || !std::isfinite(tol)) throw std::invalid_argument(fmt::format("--tol must be > 0, got {}", tol));
  const problem_study* p = study.find(problem);
  const auto names = study.problems | std::views::transform(&problem_study::name);
  if (!p)
    throw std::invalid_argument(fmt::format("problem '{}' is not in the study file '{}' (it has: {})", problem,
                                            study.record ? study.record->path : "",
                                            names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
  advice a;
  a.problem = problem;
  a.scene = scene_text(problem, p->params);
  a.metric = metric;
  a.unit = metric == "err_vel_final" ? p->unit + "/s" : p->unit;
  a.tol = tol;
  a.timed = study.timed.has_value();
  a.methods = work_precision_input(*p, metric);
  a.result = cheapest(a.methods, tol, a.timed, metric, a.unit);
  return a;
}

std::string frame_runs_missing(const study& s, const std::string& problem, double hz) {
  const std::string path = s.record ? s.record->path : "";
  const auto& studies = s.results.get<std::vector<frame_rate_study>>();
  const auto fs = std::find_if(studies.begin(), studies.end(), [&](const auto& f) { return f.problem == problem; });
  if (fs == studies.end() || !s.results.find<verdict_tables>())
    return fmt::format("the study '{}' has no frame-rate runs of {}", path, problem);
  std::vector<double> rates;
  for (const auto& r : fs->runs)
    if (std::find(rates.begin(), rates.end(), r.hz) == rates.end()) rates.push_back(r.hz);
  if (std::find(rates.begin(), rates.end(), hz) != rates.end()) return "";
  return fmt::format("the study '{}' ran {} at {} Hz only", path, problem, fmt::join(rates, ", "));
}

frame_advice advise_frame(const study& s, const std::string& problem, double hz, double tol) {
  if (!(tol > 0.0) || !std::isfinite(tol)) throw std::invalid_argument(fmt::format("--tol must be > 0, got {}", tol));
  if (!(hz > 0.0) || !std::isfinite(hz)) throw std::invalid_argument(fmt::format("--hz must be > 0, got {}", hz));
  const std::string path = s.record ? s.record->path : "";
  const auto& studies = s.results.get<std::vector<frame_rate_study>>();
  const auto* verdict = s.results.find<verdict_tables>();
  if (studies.empty() || !verdict)
    throw std::runtime_error(fmt::format(
        "cannot read study file '{}': it has no frame-rate study (written before format_version 4: run the study "
        "again)",
        path));
  const auto fs = std::find_if(studies.begin(), studies.end(), [&](const auto& f) { return f.problem == problem; });
  if (fs == studies.end())
    throw std::invalid_argument(
        fmt::format("problem '{}' has no frame-rate runs in '{}' (it has: {})", problem, path,
                    fmt::join(studies | std::views::transform(&frame_rate_study::problem), ", ")));
  frame_advice f;
  f.problem = problem;
  if (const problem_study* ps = s.find(problem)) f.scene = scene_text(problem, ps->params);
  f.hz = hz;
  f.tol = tol;
  f.cost_kind = verdict->cost_kind;
  f.unit = fs->unit;
  f.horizon = fs->horizon;
  const std::vector<frame_option> runs = frame_options(s, *fs);
  std::vector<double> rates;
  for (const auto& o : runs)
    if (std::find(rates.begin(), rates.end(), o.hz) == rates.end()) rates.push_back(o.hz);
  if (std::find(rates.begin(), rates.end(), hz) == rates.end())
    throw std::invalid_argument(
        fmt::format("--hz {:g}: the study ran {} at {} Hz only", hz, problem, fmt::join(rates, ", ")));
  std::map<std::string, frame_option> best, closest;  // per method: cheapest meeting tol; lowest error
  std::vector<std::string> order;
  std::set<std::string> untimed;  // meets the tolerance in a run the benchmark did not time
  for (const frame_option& o : runs) {
    if (o.hz != hz) continue;
    if (std::find(order.begin(), order.end(), o.method) == order.end()) order.push_back(o.method);
    if (o.substeps == 1) f.one_step.push_back(o);
    if (!o.completed || !std::isfinite(o.err_pos_max)) continue;
    if (!closest.count(o.method) || o.err_pos_max < closest[o.method].err_pos_max) closest[o.method] = o;
    if (o.err_pos_max <= tol && !std::isfinite(o.cost_per_frame)) untimed.insert(o.method);
    if (o.err_pos_max <= tol && std::isfinite(o.cost_per_frame) &&
        (!best.count(o.method) || o.cost_per_frame < best[o.method].cost_per_frame))
      best[o.method] = o;
  }
  for (const auto& m : order) {
    if (best.count(m))
      f.ranked.push_back(best[m]);
    else if (untimed.count(m))
      f.not_meeting.push_back(
          fmt::format("{}: meets it, but the benchmark did not time it on {} (no cost a frame)", m, problem));
    else if (closest.count(m))
      f.not_meeting.push_back(fmt::format("{}: best {:.3g} {} at {} substep{}", m, closest[m].err_pos_max, f.unit,
                                          closest[m].substeps, closest[m].substeps == 1 ? "" : "s"));
    else
      f.not_meeting.push_back(fmt::format("{}: diverged or failed at every substep count", m));
  }
  std::stable_sort(f.ranked.begin(), f.ranked.end(), [](const frame_option& a, const frame_option& b) {
    return a.cost_per_frame != b.cost_per_frame ? a.cost_per_frame < b.cost_per_frame : a.err_pos_max < b.err_pos_max;
  });
  return f;
}

}  // namespace stepbench

#include "judge/scan.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "core/number.hpp"
#include "judge/loop.hpp"
#include "registry/registry.hpp"

namespace stepbench {
namespace {

std::string param_unit(const std::string& problem, const std::string& param) {
  try {
    for (const auto& p : make_problem(problem)->params())
      if (p.name == param) return p.unit == "1" ? "" : " " + p.unit;
  } catch (const std::exception&) {
  }
  return "";
}

// "over k_s 10 .. 1e7 N/m (25 points, log)"; a scan of no axis is one point: "at" its scene.
std::string range_text(const scan_result& s) {
  if (s.options.axes.empty()) return "at " + scene_text(s.options.problem, s.options.fixed, s.options.fixed);
  std::vector<std::string> parts;
  for (const auto& a : s.options.axes)
    parts.push_back(fmt::format("{} {:g} .. {:g}{} ({} points{})", a.param, a.lo, a.hi,
                                param_unit(s.options.problem, a.param), a.count, a.log ? ", log" : ""));
  return fmt::format("over {}", fmt::join(parts, " x "));
}

}  // namespace

std::string scene_text(const std::string& problem, const std::map<std::string, double>& values,
                       const std::map<std::string, double>& set) {
  std::vector<std::string> out;
  std::vector<param_value> declared;
  try {
    declared = make_problem(problem)->params();
  } catch (const std::invalid_argument&) {  // a study of a problem this build lacks: its values, unnamed units
    for (const auto& [name, value] : values) declared.push_back({name, "1", "", value, value, {}, {}});
  }
  for (const auto& p : declared) {
    const auto it = values.find(p.name);
    out.push_back(fmt::format("{} = {:g}{}{}", p.name, it == values.end() ? p.value : it->second,
                              p.unit == "1" ? "" : " " + p.unit, set.count(p.name) ? " (set)" : ""));
  }
  return fmt::format("{}", fmt::join(out, ", "));
}

std::map<std::string, double> measured_eval_costs(const study& s, const std::string& problem) {
  std::map<std::string, double> out;
  const problem_study* ps = s.find(problem);
  if (!s.timed || !ps) return out;
  for (const auto& ms : ps->methods) {
    if (!offered_as_ours(ms.info.origin) || ms.info.kind != method_kind::fixed_step) continue;
    if (const double ns = measured_eval_cost_ns(*ps, ms.info.name); std::isfinite(ns)) out[ms.info.name] = ns;
  }
  return out;
}

scan_answer answer_scan(const scan_result& s, double tol) {
  scan_answer a;
  a.problem = s.options.problem;
  a.unit = s.unit;
  a.tol = tol;
  a.range = range_text(s);
  a.cost_kind = s.options.ns_per_force_eval.empty() ? "force_evals" : "time_ns";
  a.cost_source = s.options.cost_source;
  a.ns_per_force_eval = s.options.ns_per_force_eval;
  if (!a.ns_per_force_eval.empty())
    for (const auto& m : s.options.methods)
      if (!a.ns_per_force_eval.count(m)) a.uncosted.push_back(m);
  a.points = s.points.size();
  a.grid_points = s.grid_points;
  for (const auto& p : s.points) a.untrusted += p.trusted ? 0 : 1;
  // Runs by (rate, method, substeps): stability over every point (a run diverged or not
  // whatever the truth), error and cost over the points with a trusted truth.
  struct combo {
    double hz;
    std::string method;
    int substeps;
    std::size_t runs = 0, judged = 0, within = 0, skipped = 0;
    double worst = 0.0, evals = 0.0, cost = 0.0;
    std::vector<std::size_t> unstable;  // point indices
  };
  std::vector<combo> combos;
  for (const auto& r : s.runs) {
    const auto& p = s.points[r.point];
    auto it = std::find_if(combos.begin(), combos.end(), [&](const combo& c) {
      return c.hz == r.hz && c.method == r.method && c.substeps == r.substeps;
    });
    combo& c = it != combos.end()
                   ? *it
                   : combos.emplace_back(combo{r.hz, r.method, r.substeps, 0, 0, 0, 0, 0.0, 0.0, 0.0, {}});
    ++c.runs;
    const auto& m = r.row.metrics;
    if (m.diverged || m.failed) c.unstable.push_back(r.point);
    if (m.skipped) ++c.skipped;
    if (!p.trusted) continue;
    ++c.judged;
    if (m.completed() && m.err_pos_max <= tol) ++c.within;
    c.worst = m.completed() ? std::max(c.worst, m.err_pos_max) : std::numeric_limits<double>::infinity();
    const double evals = static_cast<double>(r.row.work.force_evals) / (p.horizon * r.hz);
    c.evals = std::max(c.evals, evals);
    // A method without a measured cost is not ranked: its NaN stays (std::max would drop it).
    const double cost = scan_cost(s.options, r.method, evals);
    c.cost = std::isnan(cost) || std::isnan(c.cost) ? nan : std::max(c.cost, cost);
  }
  const std::size_t trusted = a.points - a.untrusted;
  for (double hz : s.options.hz) {
    scan_choice best{hz, "", 0, nan, nan, nan};
    for (const auto& c : combos) {
      // Within the tolerance at every point with a truth, and stable at every point.
      if (c.hz != hz || c.judged != trusted || c.within != trusted || trusted == 0 || c.runs != a.points ||
          !c.unstable.empty() || c.skipped > 0 || std::isnan(c.cost))
        continue;
      if (best.method.empty() || c.cost < best.max_cost_per_frame ||
          (c.cost == best.max_cost_per_frame && c.substeps < best.substeps))
        best = {hz, c.method, c.substeps, c.worst, c.evals, c.cost};
    }
    a.choices.push_back(best);
    for (const auto& c : combos) {
      if (c.hz != hz || c.substeps != 1) continue;
      scan_break b{hz, c.method, c.unstable.size(), c.runs, ""};
      if (!c.unstable.empty() && s.options.axes.size() == 1) {
        // One axis: the unstable values as ranges of consecutive grid points.
        const auto& axis = s.options.axes[0];
        const std::string unit = param_unit(s.options.problem, axis.param);
        std::vector<std::string> spans;
        for (std::size_t k = 0; k < c.unstable.size();) {
          std::size_t e = k;
          // Consecutive in the grid (a merged --partial scan may lack points between).
          while (e + 1 < c.unstable.size() && s.points[c.unstable[e + 1]].index == s.points[c.unstable[e]].index + 1)
            ++e;
          const double lo = s.points[c.unstable[k]].values[0], hi = s.points[c.unstable[e]].values[0];
          const bool to_end = s.points[c.unstable[e]].index + 1 == s.grid_points,
                     from_start = s.points[c.unstable[k]].index == 0;
          spans.push_back(to_end && !from_start   ? fmt::format("{} >= {:.3g}{}", axis.param, lo, unit)
                          : from_start && !to_end ? fmt::format("{} <= {:.3g}{}", axis.param, hi, unit)
                          : lo == hi              ? fmt::format("{} = {:.3g}{}", axis.param, lo, unit)
                                                  : fmt::format("{} {:.3g} .. {:.3g}{}", axis.param, lo, hi, unit));
          k = e + 1;
        }
        b.where = fmt::format("diverges for {}", fmt::join(spans, ", "));
      } else if (!c.unstable.empty() && s.options.axes.empty()) {
        b.where = "diverges";
      } else if (!c.unstable.empty()) {
        std::vector<std::string> at;
        for (std::size_t k = 0; k < s.options.axes.size(); ++k)
          at.push_back(fmt::format("{} = {:.3g}", s.options.axes[k].param, s.points[c.unstable.front()].values[k]));
        b.where =
            fmt::format("diverges at {} of {} points, first at {}", c.unstable.size(), c.runs, fmt::join(at, ", "));
      } else if (c.skipped == c.runs) {
        b.where = "not run: over the work budget at every point";
      } else if (c.skipped > 0) {
        b.where = fmt::format("stable at the {} of {} points it ran (the rest over the work budget)",
                              c.runs - c.skipped, c.runs);
      } else {
        b.where = s.options.axes.empty() ? "stable" : "stable everywhere";
      }
      a.breaks.push_back(b);
    }
  }
  return a;
}

}  // namespace stepbench

#include "render/scan.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "core/work_precision.hpp"

namespace stepbench {

std::string format_scan_answer(const scan_answer& a) {
  std::string out = fmt::format(
      "{} {}, within {:g} {} (err_pos_max){}:\n", a.problem, a.range, a.tol, a.unit,
      a.points < a.grid_points
          ? fmt::format(", on {} of the grid's {} points (a shard, or a partial merge)", a.points, a.grid_points)
          : "");
  for (const auto& c : a.choices) {
    if (c.method.empty())
      out += fmt::format("  {:g} Hz: no method of the scan stays within {:g} {} {}\n", c.hz, a.tol, a.unit,
                         a.grid_points == 1 ? "at this point" : "over the whole range");
    else
      out += fmt::format(
          "  {:g} Hz: {} with {} stays stable and within {:g} {} {} (worst {:.3g} {}, "
          "{:.4g} force evaluations a frame at most{})\n",
          c.hz, c.method, c.substeps == 1 ? std::string("one step a frame") : fmt::format("{} substeps", c.substeps),
          a.tol, a.unit,
          a.untrusted == 0
              ? std::string(a.grid_points == 1 ? "here" : "everywhere")
              : fmt::format("at the {} points with a truth (stable at all {})", a.points - a.untrusted, a.points),
          c.worst_err, a.unit, c.max_force_evals_per_frame,
          a.cost_kind == "time_ns" ? fmt::format(", {} a frame", format_time_ns(c.max_cost_per_frame)) : "");
  }
  if (a.cost_kind == "time_ns") {
    std::vector<std::string> chosen;  // each answer's ns per evaluation, once
    for (const auto& c : a.choices) {
      const auto text =
          fmt::format("{} {:.3g} ns", c.method, c.method.empty() ? 0.0 : a.ns_per_force_eval.at(c.method));
      if (!c.method.empty() && std::find(chosen.begin(), chosen.end(), text) == chosen.end()) chosen.push_back(text);
    }
    out += fmt::format("cost a frame: force evaluations x the method's ns per evaluation, {}{}\n",
                       a.cost_source == cost_timed_here
                           ? std::string(cost_timed_here)
                           : fmt::format("measured on {} by the benchmark in '{}'", a.problem, a.cost_source),
                       chosen.empty() ? "" : fmt::format(" ({})", fmt::join(chosen, ", ")));
    if (!a.uncosted.empty())
      out += fmt::format("not ranked: '{}' has no timed rows of {} on {}\n", a.cost_source, fmt::join(a.uncosted, ", "),
                         a.problem);
  } else
    out += fmt::format("cost a frame: force evaluations (no timed study of {} given: `--costs FILE` ranks by time)\n",
                       a.problem);
  out += "At one step a frame:\n";
  for (const auto& b : a.breaks) out += fmt::format("  {:g} Hz  {:<22} {}\n", b.hz, b.method, b.where);
  if (a.untrusted > 0)
    out += fmt::format(
        "{} of {} points have no trusted truth: their runs are judged on stability alone, the tolerance on the other "
        "{} (see the scan's points table)\n",
        a.untrusted, a.points, a.points - a.untrusted);
  return out;
}

}  // namespace stepbench

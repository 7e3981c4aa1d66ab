#include "core/work_precision.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stepbench {
namespace {

bool qualifies(const wp_row& r, double target, bool timed) {
  return r.completed && std::isfinite(r.error) && r.error <= target && !(timed && r.cut);
}

std::string what_param(method_kind kind) { return kind == method_kind::adaptive ? "tolerance" : "dt"; }

}  // namespace

bool is_error_metric(std::string_view name) {
  return std::find(std::begin(error_metrics), std::end(error_metrics), name) != std::end(error_metrics);
}

std::string format_param(method_kind kind, double param) {
  return kind == method_kind::adaptive ? fmt::format("tol {:g}", param) : fmt::format("dt {:g} s", param);
}

std::string format_time_ns(double ns) {
  if (!std::isfinite(ns)) return "n/a";
  if (ns >= 1e9) return fmt::format("{:.3g} s", ns * 1e-9);
  if (ns >= 1e6) return fmt::format("{:.3g} ms", ns * 1e-6);
  if (ns >= 1e3) return fmt::format("{:.3g} us", ns * 1e-3);
  return fmt::format("{:.3g} ns", ns);
}

std::optional<wp_pick> cheapest_result::answer(const std::vector<wp_method>& methods) const {
  for (const auto& p : ranked)
    if (methods[p.method].origin != method_origin::baseline) return p;
  return std::nullopt;
}

cheapest_result cheapest(const std::vector<wp_method>& methods, double target, bool timed, const std::string& metric,
                         const std::string& unit, wp_candidates candidates) {
  if (!(target > 0.0) || !std::isfinite(target))
    throw std::invalid_argument(fmt::format("the target error must be > 0, got {}", target));
  cheapest_result r;
  r.target = target;
  const auto competes = [&](const wp_method& m) {
    return candidates == wp_candidates::every_method ||
           std::any_of(m.rows.begin(), m.rows.end(), [](const wp_row& row) { return std::isfinite(row.time_ns); });
  };
  // Time is the cost only if it can rank every qualifying row; otherwise the counted
  // force evaluations, which every row has.
  bool all_timed = timed;
  for (const auto& m : methods)
    if (competes(m))
      for (const auto& row : m.rows)
        if (qualifies(row, target, timed) && !(std::isfinite(row.time_ns) && row.time_ns > 0.0)) all_timed = false;
  r.cost = all_timed ? "time_ns" : "force_evals";
  auto cost_of = [&](const wp_row& row) { return all_timed ? row.time_ns : row.force_evals; };

  std::optional<wp_pick> best_achieved;
  for (std::size_t mi = 0; mi < methods.size(); ++mi) {
    const auto& m = methods[mi];
    if (!competes(m)) continue;
    auto make_pick = [&](std::size_t ri) {
      wp_pick p;
      p.method = mi;
      p.row = ri;
      p.cost = cost_of(m.rows[ri]);
      for (const auto& d : m.rows) {
        if (!d.diverged) continue;
        ++p.diverged_rows;
        if (!p.largest_diverged || d.param > *p.largest_diverged) p.largest_diverged = d.param;
        if (!p.smallest_diverged || d.param < *p.smallest_diverged) p.smallest_diverged = d.param;
      }
      return p;
    };
    std::optional<std::size_t> best, lowest;
    for (std::size_t ri = 0; ri < m.rows.size(); ++ri) {
      const auto& row = m.rows[ri];
      if (row.completed && std::isfinite(row.error) && (!lowest || row.error < m.rows[*lowest].error)) lowest = ri;
      if (!qualifies(row, target, timed)) continue;
      // Cheapest; on a tie the more accurate row.
      if (!best || cost_of(row) < cost_of(m.rows[*best]) ||
          (cost_of(row) == cost_of(m.rows[*best]) && row.error < m.rows[*best].error))
        best = ri;
    }
    if (lowest && m.origin != method_origin::baseline &&
        (!best_achieved || m.rows[*lowest].error < methods[best_achieved->method].rows[best_achieved->row].error))
      best_achieved = make_pick(*lowest);
    if (best) {
      r.ranked.push_back(make_pick(*best));
      continue;
    }
    std::string reason;
    if (!lowest) {
      bool any_diverged = false;
      for (const auto& d : m.rows) any_diverged = any_diverged || d.diverged;
      reason = m.rows.empty() ? "no rows in the study"
               : any_diverged ? fmt::format("diverged or failed at every {}", what_param(m.kind))
                              : fmt::format("failed at every {}", what_param(m.kind));
    } else if (m.rows[*lowest].error <= target) {  // accurate enough, but every such row was cut
      reason = fmt::format("too slow: cut by the time budget (would reach {} {:.3g} {} at {})", metric,
                           m.rows[*lowest].error, unit, format_param(m.kind, m.rows[*lowest].param));
    } else {
      reason = fmt::format("too inaccurate: best {} {:.3g} {} at {}", metric, m.rows[*lowest].error, unit,
                           format_param(m.kind, m.rows[*lowest].param));
    }
    r.excluded.push_back({mi, reason});
  }
  std::stable_sort(r.ranked.begin(), r.ranked.end(), [&](const wp_pick& a, const wp_pick& b) {
    if (a.cost != b.cost) return a.cost < b.cost;
    const double ea = methods[a.method].rows[a.row].error, eb = methods[b.method].rows[b.row].error;
    if (ea != eb) return ea < eb;
    return methods[a.method].name < methods[b.method].name;
  });
  if (!r.answer(methods)) r.best_achieved = best_achieved;
  return r;
}

std::vector<front_point> pareto_front(const std::vector<wp_method>& methods, bool by_time, bool timed) {
  std::vector<front_point> pts;
  for (std::size_t mi = 0; mi < methods.size(); ++mi) {
    if (methods[mi].origin == method_origin::baseline) continue;
    for (std::size_t ri = 0; ri < methods[mi].rows.size(); ++ri) {
      const auto& r = methods[mi].rows[ri];
      const double cost = by_time ? r.time_ns : r.force_evals;
      if (!r.completed || !std::isfinite(r.error) || !(std::isfinite(cost) && cost > 0.0) || (timed && r.cut)) continue;
      pts.push_back({mi, ri, cost, r.error});
    }
  }
  // By cost, then error; a point joins when it beats every cheaper point's error.
  std::sort(pts.begin(), pts.end(), [](const front_point& a, const front_point& b) {
    return a.cost != b.cost ? a.cost < b.cost : a.error < b.error;
  });
  std::vector<front_point> front;
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : pts)
    if (p.error < best * (1.0 - 1e-6)) {
      front.push_back(p);
      best = p.error;
    }
  return front;
}

}  // namespace stepbench

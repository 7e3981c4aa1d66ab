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

double cost_of(const wp_row& r, bool by_time) { return by_time ? r.time_ns : r.force_evals; }

// A row on a method's curve: completed, its error finite (an error of exactly 0, a method
// exact for the problem, meets every target and bounds the cost like any row that does),
// its cost measured and, in a timed study, its timing not cut.
bool on_curve(const wp_row& r, bool by_time, bool timed) {
  const double c = cost_of(r, by_time);
  return r.completed && std::isfinite(r.error) && r.error >= 0.0 && std::isfinite(c) && c > 0.0 && !(timed && r.cut);
}

// The pick at measured row i. The spread of its cost: the fastest and slowest repetition
// when timed and recorded, else the cost itself.
wp_pick at_row(const wp_method& m, std::size_t i, bool by_time) {
  const wp_row& r = m.rows[i];
  const auto spread = [&](double t) { return by_time && std::isfinite(t) && t > 0.0 ? t : cost_of(r, by_time); };
  wp_pick p;
  p.row = i;
  p.cost = cost_of(r, by_time);
  p.cost_lo = spread(r.time_lo);
  p.cost_hi = spread(r.time_hi);
  p.param = r.param;
  p.error = r.error;
  p.time_ns = r.time_ns;
  p.force_evals = r.force_evals;
  return p;
}

}  // namespace

bool is_error_metric(std::string_view name) {
  return std::find(std::begin(error_metrics), std::end(error_metrics), name) != std::end(error_metrics);
}

std::string format_param(method_kind kind, double param) {
  return kind == method_kind::adaptive ? fmt::format("tol {:g}", param) : fmt::format("dt {:g} s", param);
}

std::string format_time_ns(double ns) {
  if (!std::isfinite(ns)) return "n/a";
  // Rounded to three digits before the unit is chosen: 999.7 ns is "1 us", not "1e+03 ns".
  ns = std::stod(fmt::format("{:.3g}", ns));
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

std::optional<wp_pick> at_equal_error(const wp_method& m, double target, bool by_time, bool timed) {
  // The curve: the usable rows in ladder order (coarse to fine, as the study stores them).
  std::vector<std::size_t> curve;
  for (std::size_t i = 0; i < m.rows.size(); ++i)
    if (on_curve(m.rows[i], by_time, timed)) curve.push_back(i);
  std::optional<wp_pick> best;
  const auto consider = [&](const wp_pick& p) {
    if (!best || p.cost < best->cost) best = p;
  };
  // Upper bounds: every measured row at or under the target (the curve is not
  // extrapolated beyond the coarsest, and on a curve whose cost does not rise steadily,
  // an adaptive method's or a noisy timing's, a measured row may undercut a crossing).
  for (const std::size_t i : curve)
    if (m.rows[i].error <= target) consider(at_row(m, i, by_time));
  // Log-log interpolation between neighbours that bracket the target (both errors
  // positive: a row of error 0 is a bound above, not a point of a log-log line).
  const double lt = std::log(target);
  for (std::size_t k = 0; k + 1 < curve.size(); ++k) {
    const auto &a = m.rows[curve[k]], &b = m.rows[curve[k + 1]];
    const bool brackets = (a.error >= target && b.error <= target) || (a.error <= target && b.error >= target);
    if (!brackets || a.error == b.error || a.error == 0.0 || b.error == 0.0) continue;
    const double s = (lt - std::log(a.error)) / (std::log(b.error) - std::log(a.error));
    const auto lerp = [&](double va, double vb) {
      if (!(std::isfinite(va) && std::isfinite(vb) && va > 0.0 && vb > 0.0))
        return std::numeric_limits<double>::quiet_NaN();
      return std::exp(std::log(va) + s * (std::log(vb) - std::log(va)));
    };
    const wp_pick pa = at_row(m, curve[k], by_time), pb = at_row(m, curve[k + 1], by_time);
    wp_pick p = a.error <= b.error ? pa : pb;  // the row: the more accurate of the two
    for (double wp_pick::*f : {&wp_pick::cost, &wp_pick::cost_lo, &wp_pick::cost_hi, &wp_pick::param, &wp_pick::time_ns,
                               &wp_pick::force_evals})
      p.*f = lerp(pa.*f, pb.*f);
    p.error = target;
    p.interpolated = true;
    consider(p);
  }
  return best;
}

double equal_error_threshold(const cost_band& a, const cost_band& b, bool timed) {
  if (!timed) return 1e-9;
  const auto spread = [](const cost_band& c) { return c.hi > c.lo ? (c.hi - c.lo) / c.cost : 0.0; };
  const bool both_spread = a.hi > a.lo && b.hi > b.lo;
  return std::max(both_spread ? timing_noise_floor : timing_single_run_floor,
                  timing_spread_multiple * std::max(spread(a), spread(b)));
}

const char* compare_at_equal_error(const cost_band& a, const cost_band& b, bool timed) {
  const double threshold = equal_error_threshold(a, b, timed);
  const double ratio = a.cost / b.cost;
  if (ratio < 1.0 / (1.0 + threshold)) return "ahead";
  if (ratio > 1.0 + threshold) return "behind";
  return "within spread";
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
  // Time is the cost only if it can rank every method that reaches the target: every
  // completed row of a competing method that meets the target has a time (a coarser
  // neighbour without one leaves the crossing off the curve, and the method is charged
  // its coarsest timed row that meets the target: an upper bound, never a guess).
  bool all_timed = timed;
  for (const auto& m : methods)
    if (competes(m))
      for (const auto& row : m.rows)
        if (qualifies(row, target, timed) && !(std::isfinite(row.time_ns) && row.time_ns > 0.0)) all_timed = false;
  r.cost = all_timed ? "time_ns" : "force_evals";

  std::optional<wp_pick> best_achieved;
  for (std::size_t mi = 0; mi < methods.size(); ++mi) {
    const auto& m = methods[mi];
    if (!competes(m)) continue;
    auto with_margin = [&](wp_pick p) {
      p.method = mi;
      for (const auto& d : m.rows) {
        if (!d.diverged) continue;
        ++p.diverged_rows;
        if (!p.largest_diverged || d.param > *p.largest_diverged) p.largest_diverged = d.param;
        if (!p.smallest_diverged || d.param < *p.smallest_diverged) p.smallest_diverged = d.param;
      }
      return p;
    };
    std::optional<std::size_t> lowest;
    for (std::size_t ri = 0; ri < m.rows.size(); ++ri) {
      const auto& row = m.rows[ri];
      if (row.completed && std::isfinite(row.error) && (!lowest || row.error < m.rows[*lowest].error)) lowest = ri;
    }
    if (lowest && m.origin != method_origin::baseline &&
        (!best_achieved || m.rows[*lowest].error < methods[best_achieved->method].rows[best_achieved->row].error)) {
      wp_pick p = at_row(m, *lowest, all_timed);
      p.cost_lo = p.cost_hi = p.cost;
      best_achieved = with_margin(p);
    }
    if (const auto p = at_equal_error(m, target, all_timed, timed)) {
      r.ranked.push_back(with_margin(*p));
      continue;
    }
    std::string reason;
    if (!lowest) {
      const bool any_diverged = std::any_of(m.rows.begin(), m.rows.end(), [](const wp_row& d) { return d.diverged; });
      reason = m.rows.empty() ? "no rows in the study"
               : any_diverged ? fmt::format("diverged or failed at every {}", param_name(m.kind))
                              : fmt::format("failed at every {}", param_name(m.kind));
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
    if (a.error != b.error) return a.error < b.error;
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
      if (on_curve(r, by_time, timed)) pts.push_back({mi, ri, cost_of(r, by_time), r.error});
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

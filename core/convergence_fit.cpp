#include "core/convergence_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/statistics.hpp"

namespace stepbench {

double roundoff_bound(long steps, double scale) {
  return 8.0 * std::numeric_limits<double>::epsilon() * static_cast<double>(std::max(1L, steps)) * scale;
}

double roundoff_noise(long steps, double scale) {
  return std::numeric_limits<double>::epsilon() * std::sqrt(static_cast<double>(std::max(1L, steps))) * scale;
}

int declared_order_holds(double declared, const fit_result& fit) {
  if (!std::isfinite(declared) || fit.state != fit_result::status::fitted) return -1;
  return std::abs(fit.order - declared) <= declared_order_slack ? 1 : 0;
}

fit_result fit_order(const fit_input& in) {
  fit_result out;
  out.order = std::numeric_limits<double>::quiet_NaN();
  const int n = static_cast<int>(in.dt.size());

  bool all_roundoff = n > 0;
  for (int k = 0; k < n; ++k)
    if (in.incomplete[k] || !(in.error[k] <= roundoff_bound(in.steps[k], in.scale))) all_roundoff = false;
  // The bound grows with n, so on a ladder of huge step counts a converging method can sit
  // under it too. Such errors fall as dt does and stand clearly above typical round-off
  // noise; an exact method's errors are noise (they may fall too, from 1e-17 relative
  // upwards, as the rounding of O(dt) terms shrinks).
  auto slope = [&](int k) { return std::log(in.error[k] / in.error[k + 1]) / std::log(in.dt[k] / in.dt[k + 1]); };
  std::vector<double> local;
  for (int k = 0; k + 1 < n; ++k)
    if (in.error[k] > 0.0 && in.error[k + 1] > 0.0) local.push_back(slope(k));
  const bool converging =
      !local.empty() && median(local) > 0.5 && in.error[0] > 100.0 * roundoff_noise(in.steps[0], in.scale);
  if (all_roundoff && !converging) {
    out.state = fit_result::status::exact;
    out.note = "error at round-off at every level: the method is exact for this problem";
    return out;
  }

  auto usable = [&](int k) {
    return !in.incomplete[k] && std::isfinite(in.error[k]) &&
           in.error[k] > 100.0 * roundoff_noise(in.steps[k], in.scale) && in.error[k] < 0.1 * in.scale;
  };
  // The window grown coarser from the pair (end - 1, end) while each local slope stays
  // within 0.1 of the median so far. It starts at the finest usable pair; when that pair
  // is the odd one out (the first touch of round-off) and leaves fewer than three levels,
  // the next coarser end is tried. A pair whose error does not fall (slope below 0.5) is
  // an error floor, not an asymptotic range, however consistent its neighbours (an
  // eighth-order method on the orbit: three levels of accumulated round-off at slope -0.6).
  // First pass: an end after which the error stops falling is skipped too. The rise that
  // follows is round-off taking over, and it reaches the levels just before it (XPBD's
  // velocity (x - x_prev) / h divides position round-off by h: at 2^19 substeps its slope
  // 1.11, 1.14 over the last two levels before the rise, 1.00 over the twelve before).
  // When that leaves no window, the second pass takes the window the first rule gives.
  auto falls_after = [&](int end) {
    return end + 1 >= n || in.incomplete[end + 1] || !std::isfinite(in.error[end + 1]) || !(in.error[end + 1] > 0.0) ||
           slope(end) >= 0.5;
  };
  int first = -1, last = -1;
  for (int pass = 0; pass < 2 && first < 0; ++pass)
    for (int end = n - 1; end >= 2 && first < 0; --end) {
      if (!usable(end) || !usable(end - 1) || !(slope(end - 1) >= 0.5)) continue;
      if (pass == 0 && !falls_after(end)) continue;
      std::vector<double> slopes{slope(end - 1)};
      int start = end - 1;
      while (start > 0 && usable(start - 1) && std::abs(slope(start - 1) - median(slopes)) <= 0.1) {
        --start;
        slopes.push_back(slope(start));
      }
      if (end - start + 1 >= 3) first = start, last = end;
    }
  if (first < 0) {
    out.note =
        "fewer than three consecutive levels in the asymptotic range (the rest diverged, are at round-off "
        "or pre-asymptotic)";
    return out;
  }
  // Least squares for log10 e = p log10 dt + c.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const int m = last - first + 1;
  for (int k = first; k <= last; ++k) {
    const double x = std::log10(in.dt[k]), y = std::log10(in.error[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
    out.levels.push_back(k);
  }
  out.order = (m * sxy - sx * sy) / (m * sxx - sx * sx);
  out.intercept = (sy - out.order * sx) / m;
  double ss = 0;
  for (int k = first; k <= last; ++k) {
    const double r = std::log10(in.error[k]) - (out.order * std::log10(in.dt[k]) + out.intercept);
    ss += r * r;
  }
  out.residual = std::sqrt(ss / m);
  out.state = fit_result::status::fitted;
  return out;
}

}  // namespace stepbench

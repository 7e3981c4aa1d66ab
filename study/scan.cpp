// What a scan's results derive from themselves: an axis' values, the cheapest run at
// each point and rate.
#include "study/scan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stepbench {

std::vector<double> scan_axis::values() const {
  // Log axes in powers of ten, so that whole decades are exact (glibc's pow is exact
  // for 10^k); both ends are the values given.
  std::vector<double> out;
  for (int i = 0; i < count; ++i) {
    const double s = count == 1 ? 0.0 : static_cast<double>(i) / (count - 1);
    out.push_back(i == 0           ? lo
                  : i == count - 1 ? hi
                  : log            ? std::pow(10.0, std::log10(lo) + s * (std::log10(hi) - std::log10(lo)))
                                   : lo + s * (hi - lo));
    if (whole) out.back() = std::round(out.back());
  }
  return out;
}

double scan_cost(const scan_options& o, const std::string& method, double force_evals) {
  if (o.ns_per_force_eval.empty()) return force_evals;
  const auto it = o.ns_per_force_eval.find(method);
  return it == o.ns_per_force_eval.end() ? std::numeric_limits<double>::quiet_NaN() : force_evals * it->second;
}

// The cheapest run meeting the tolerance at each point and rate: least scan_cost (the same
// frames at one rate, so the totals compare), then fewer substeps.
void compute_best(scan_result& s) {
  const auto& hz = s.options.hz;
  std::vector<const scan_run*> pick(s.points.size() * hz.size(), nullptr);
  const auto cost = [&](const scan_run& r) {
    return scan_cost(s.options, r.method, static_cast<double>(r.row.work.force_evals));
  };
  for (const auto& r : s.runs) {
    const auto rate = static_cast<std::size_t>(std::find(hz.begin(), hz.end(), r.hz) - hz.begin());
    if (rate == hz.size() || !r.row.metrics.completed() || !(r.row.metrics.err_pos_max <= s.options.tol) ||
        std::isnan(cost(r)))
      continue;
    const scan_run*& p = pick[r.point * hz.size() + rate];
    if (!p || cost(r) < cost(*p) || (cost(r) == cost(*p) && r.substeps < p->substeps)) p = &r;
  }
  s.best.clear();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < s.points.size(); ++i)
    for (std::size_t k = 0; k < hz.size(); ++k) {
      scan_best b{i, hz[k], "", 0, nan, nan};
      if (const scan_run* p = pick[i * hz.size() + k]) {
        b.method = p->method;
        b.substeps = p->substeps;
        b.err_pos_max = p->row.metrics.err_pos_max;
        b.force_evals_per_frame = static_cast<double>(p->row.work.force_evals) / (s.points[i].horizon * hz[k]);
      }
      s.best.push_back(b);
    }
}

}  // namespace stepbench

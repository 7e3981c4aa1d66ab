// What a scan's results derive from themselves: an axis' values, the cheapest run at
// each point and rate.
#include "study/scan.hpp"

#include <cmath>

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

// The cheapest run meeting the tolerance at each point and rate: fewest force
// evaluations (the same frames at one rate, so the total compares), then fewer substeps.
void compute_best(scan_result& s) {
  const auto& hz = s.options.hz;
  std::vector<const scan_run*> pick(s.points.size() * hz.size(), nullptr);
  for (const auto& r : s.runs) {
    const auto rate = static_cast<std::size_t>(std::find(hz.begin(), hz.end(), r.hz) - hz.begin());
    if (rate == hz.size() || !r.row.metrics.completed() || !(r.row.metrics.err_pos_max <= s.options.tol)) continue;
    const scan_run*& p = pick[r.point * hz.size() + rate];
    if (!p || r.row.work.force_evals < p->row.work.force_evals ||
        (r.row.work.force_evals == p->row.work.force_evals && r.substeps < p->substeps))
      p = &r;
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

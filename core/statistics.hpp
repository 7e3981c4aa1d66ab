#pragma once
// Small statistics used in more than one place (the order fit, the benchmark's
// repetitions, the compare gate): one definition each.
#include <algorithm>
#include <limits>
#include <vector>

namespace stepbench {

// Median of the values (the mean of the middle two for an even count); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace stepbench

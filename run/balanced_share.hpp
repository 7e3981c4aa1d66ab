#pragma once
// Shard k of n of a list of items with counted costs: the greedy longest-processing-time
// rule (largest cost first, each to the least-loaded shard, ties in list order and to the
// lowest shard), deterministic on every machine. Used by `scan --shard` (grid points,
// sized by their coordinates) and `sweep --shard` (problems, by their counted work).
#include <algorithm>
#include <cstddef>
#include <vector>

namespace stepbench {

// The indices of the items shard k (0-based) of n gets, in list order.
inline std::vector<std::size_t> balanced_share(const std::vector<double>& cost, int k, int n) {
  std::vector<std::size_t> order(cost.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cost[a] > cost[b]; });
  std::vector<double> load(static_cast<std::size_t>(n), 0.0);
  std::vector<std::size_t> mine;
  for (std::size_t i : order) {
    const auto least = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[least] += cost[i];
    if (least == static_cast<std::size_t>(k)) mine.push_back(i);
  }
  std::sort(mine.begin(), mine.end());
  return mine;
}

}  // namespace stepbench

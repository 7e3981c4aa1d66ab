#pragma once
// Whether a sequence holds a value (C++23's std::ranges::contains, for C++20).
#include <algorithm>

namespace stepbench {

template <class Range, class T>
bool contains(const Range& r, const T& x) {
  return std::find(std::begin(r), std::end(r), x) != std::end(r);
}

}  // namespace stepbench

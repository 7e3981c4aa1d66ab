#pragma once
// Counts in words: "1 row", "3 rows".
#include <fmt/format.h>

#include <cstddef>
#include <string>
#include <string_view>

namespace stepbench {

inline std::string plural(std::size_t n, std::string_view one, std::string_view many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

}  // namespace stepbench

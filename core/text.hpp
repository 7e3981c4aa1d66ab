#pragma once
// Text helpers: counts in words ("1 row", "3 rows") and lists split at a separator.
#include <fmt/format.h>

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace stepbench {

inline std::string plural(std::size_t n, std::string_view one, std::string_view many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

// The pieces of `text` between the separators, empty ones kept: "a,,b" -> a, "", b; "" -> one
// empty piece (a command line's list, checked piece by piece). They view `text`.
inline std::vector<std::string_view> split(std::string_view text, char sep) {
  std::vector<std::string_view> out;
  for (std::size_t start = 0;;) {
    const auto at = text.find(sep, start);
    out.push_back(text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
    if (at == std::string_view::npos) return out;
    start = at + 1;
  }
}

// A list a study file stores as one string: "" is the empty list, otherwise split's pieces, copied.
inline std::vector<std::string> stored_list(std::string_view text, char sep) {
  std::vector<std::string> out;
  if (!text.empty())
    for (const auto piece : split(text, sep)) out.emplace_back(piece);
  return out;
}

}  // namespace stepbench

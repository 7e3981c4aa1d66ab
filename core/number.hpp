#pragma once
// A number as the command line and --set take it: the whole text, and finite. One rule
// for every option (cli/args.cpp's parse_number) and every parameter value
// (core/parameter.cpp's param_value::parse).
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

namespace stepbench {

// The value of a measure that does not apply or was not taken.
inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();

inline std::optional<double> finite_number(std::string_view text) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace stepbench

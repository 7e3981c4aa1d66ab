#include "core/parse.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace stepbench {

double parse_number(std::string_view text, std::string_view what) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(value))
    throw std::invalid_argument(fmt::format("{} must be a finite number, got '{}'", what, text));
  return value;
}

std::pair<std::string, double> parse_assignment(std::string_view text) {
  const auto eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
    throw std::invalid_argument(fmt::format("malformed --set '{}': expected name=value", text));
  const std::string name(text.substr(0, eq));
  return {name, parse_number(text.substr(eq + 1), fmt::format("--set {}", name))};
}

void add_override(std::map<std::string, std::map<std::string, double>>& overrides, const std::string& text,
                  const std::vector<std::string>& selected_problems) {
  auto [name, value] = parse_assignment(text);
  std::string problem;
  if (const auto dot = name.find('.'); dot != std::string::npos) {
    problem = name.substr(0, dot);
    name = name.substr(dot + 1);
    if (problem.empty() || name.empty())
      throw std::invalid_argument(fmt::format("--set {}: expected problem.name=value", text));
  } else if (selected_problems.size() == 1) {
    problem = selected_problems.front();
  } else {
    throw std::invalid_argument(
        fmt::format("--set {}: name the problem (problem.{}=value) or select one --problem", text, name));
  }
  overrides[problem][name] = value;
}

}  // namespace stepbench

#include "core/parameter.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <stdexcept>

#include "core/number.hpp"

namespace stepbench {

std::string constraint::text() const {
  const bool lo_inf = std::isinf(lo), hi_inf = std::isinf(hi);
  if (whole) {
    if (hi_inf) return fmt::format("a whole number from {}", lo);
    return fmt::format("a whole number from {} to {}", lo, hi);
  }
  if (lo_inf && hi_inf) return "finite";
  if (hi_inf) {
    if (lo == 0.0 && !lo_closed) return "a positive finite number";
    return fmt::format("finite and {} {}", lo_closed ? ">=" : ">", lo);
  }
  if (lo_inf) return fmt::format("finite and {} {}", hi_closed ? "<=" : "<", hi);
  return fmt::format("in {}{}, {}{}", lo_closed ? '[' : '(', lo, hi, hi_closed ? ']' : ')');
}

std::vector<named_value> contact_mode_names() {
  return {{"end_of_step", 0.0, "test for contact after each step, respond there"},
          {"locate", 1.0, "find the contact time inside the step, respond there, finish the step"}};
}

std::string param_value::value_name() const {
  for (const auto& n : names)
    if (n.value == value) return n.name;
  return {};
}

std::string param_value::check(double v) const {
  if (allowed.admits(v)) return {};
  if (!names.empty() && names.size() <= 4) {
    std::vector<std::string> options;
    for (const auto& n : names) options.push_back(fmt::format("{:g} ({})", n.value, n.name));
    return fmt::format("{} must be {}", name, fmt::join(options, " or "));
  }
  return fmt::format("{} must be {}", name, allowed.text());
}

double param_value::parse(std::string_view text, std::string_view qualified_name) const {
  for (const auto& n : names)
    if (n.name == text) return n.value;
  if (const auto v = finite_number(text)) return *v;
  if (names.empty())
    throw std::invalid_argument(fmt::format("--set {} must be a finite number, got '{}'", qualified_name, text));
  std::vector<std::string_view> valid;
  for (const auto& n : names) valid.push_back(n.name);
  throw std::invalid_argument(fmt::format("--set {}: '{}' is neither a number nor a name it takes ({})", qualified_name,
                                          text, fmt::join(valid, ", ")));
}

std::string check_params(std::span<const param_value> values) {
  for (const auto& q : values)
    if (auto why = q.check(q.value); !why.empty()) return why;
  return {};
}

}  // namespace stepbench

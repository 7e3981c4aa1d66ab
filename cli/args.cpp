#include "cli/args.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <ranges>
#include <stdexcept>
#include <vector>

#include "core/number.hpp"
#include "registry/registry.hpp"

namespace stepbench {

double parse_number(std::string_view text, std::string_view what) {
  if (const auto value = finite_number(text)) return *value;
  throw std::invalid_argument(fmt::format("{} must be a finite number, got '{}'", what, text));
}

double parse_positive(std::string_view text, std::string_view what) {
  const double value = parse_number(text, what);
  if (!(value > 0.0)) throw std::invalid_argument(fmt::format("{} must be > 0, got {}", what, text));
  return value;
}

std::string count_of(long long n, std::string_view singular) {
  return fmt::format("{} {}{}", n, singular, n == 1 ? "" : "s");
}

void add_override(parameter_overrides& out, std::string_view text, std::span<const std::string> selected) {
  const auto eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
    throw std::invalid_argument(fmt::format("malformed --set '{}': expected problem.name=value", text));
  const std::string_view target = text.substr(0, eq), value_text = text.substr(eq + 1);
  std::string problem, name;
  if (const auto dot = target.find('.'); dot != std::string_view::npos) {
    problem = target.substr(0, dot);
    name = target.substr(dot + 1);
    if (problem.empty() || name.empty())
      throw std::invalid_argument(fmt::format("malformed --set '{}': expected problem.name=value", text));
  } else if (selected.size() == 1) {
    problem = selected.front();
    name = target;
  } else {
    throw std::invalid_argument(fmt::format(
        "--set {}: name the problem (problem.{}=value): {}", text, target,
        selected.empty() ? "every problem is selected" : fmt::format("{} problems are selected", selected.size())));
  }
  auto instance = make_problem(problem);  // throws, naming an unknown problem
  if (!selected.empty() && std::find(selected.begin(), selected.end(), problem) == selected.end())
    throw std::invalid_argument(fmt::format("--set {}: problem {} is not selected", text, problem));
  const auto params = instance->params();
  const auto it = std::find_if(params.begin(), params.end(), [&](const param_value& q) { return q.name == name; });
  if (it == params.end())
    throw std::invalid_argument(fmt::format("--set {}: unknown parameter '{}' for problem {} (known: {})", text, name,
                                            problem,
                                            fmt::join(params | std::views::transform(&param_value::name), ", ")));
  const std::string qualified = problem + "." + name;
  const double value = it->parse(value_text, qualified);
  if (auto why = it->check(value); !why.empty())
    throw std::invalid_argument(fmt::format("--set {}={}: {}", qualified, value_text, why));
  out[problem][name] = value;
}

void parse_shard(std::string_view text, int& index, int& count) {
  const auto slash = text.find('/');
  if (slash == std::string_view::npos) throw std::invalid_argument(fmt::format("--shard {}: expected K/N", text));
  const double k = parse_number(text.substr(0, slash), "--shard K");
  const double n = parse_number(text.substr(slash + 1), "--shard N");
  if (!(n >= 1 && n <= 1e6 && n == std::floor(n) && k >= 1 && k <= n && k == std::floor(k)))
    throw std::invalid_argument(fmt::format("--shard {}: K and N must be whole numbers with 1 <= K <= N", text));
  index = static_cast<int>(k) - 1;
  count = static_cast<int>(n);
}

}  // namespace stepbench

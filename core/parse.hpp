#pragma once
// Strict parsing of command-line values: a number is the whole string or an error.
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace stepbench {

// Parses a finite double; throws std::invalid_argument("<what> must be a number, got '<text>'").
double parse_number(std::string_view text, std::string_view what);

// Splits "name=value" (value a finite number); throws std::invalid_argument naming the
// malformed assignment.
std::pair<std::string, double> parse_assignment(std::string_view text);

// Adds `problem.name=value` (or `name=value` when exactly one problem is selected) to
// the overrides map; throws std::invalid_argument for a malformed assignment.
void add_override(std::map<std::string, std::map<std::string, double>>& overrides, const std::string& text,
                  const std::vector<std::string>& selected_problems);

}  // namespace stepbench

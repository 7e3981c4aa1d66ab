#pragma once
// Command-line values, parsed once for every command of `stepbench` and for
// stepbench_bench: a number is the whole string or an error, and `--set` has one grammar.
#include <map>
#include <span>
#include <string>
#include <string_view>

namespace stepbench {

// Parses a finite double; throws std::invalid_argument("<what> must be a finite number, got '<text>'").
double parse_number(std::string_view text, std::string_view what);
// A number > 0, as parse_number; else throws std::invalid_argument("<what> must be > 0, got <text>").
double parse_positive(std::string_view text, std::string_view what);

// Parameter values by problem, then by parameter name: what every --set adds to.
using parameter_overrides = std::map<std::string, std::map<std::string, double>>;

// One `--set`: `problem.name=value`, or `name=value` when exactly one problem is
// selected (`selected` empty means every problem). The value is a number or a name the
// parameter takes (`sliding_block.material=steel_on_steel`). Throws std::invalid_argument
// in one line naming what is wrong: an ambiguous unqualified name, an unknown problem or
// parameter (listing the known ones), a problem not selected, a value that is neither a
// number nor a name the parameter takes (listing them), or a value outside the
// parameter's declared constraint.
void add_override(parameter_overrides& out, std::string_view text, std::span<const std::string> selected);

// `--shard K/N`: shard K of N, 1 <= K <= N <= 10^6, into the 0-based `index` and `count`.
// Throws std::invalid_argument("--shard <text>: ...") on anything else.
void parse_shard(std::string_view text, int& index, int& count);

// A count and its noun, the plural (an s) when the count is not one: "1 step", "2 steps".
std::string count_of(long long n, std::string_view singular);

}  // namespace stepbench

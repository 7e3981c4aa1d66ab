#pragma once
// `stepbench compare`'s report of a comparison (judge/compare.hpp) as readable text or as
// Markdown (a CI job summary, a pull-request comment): every section one table, drawn by
// the command line's one table renderer (render/table_render.hpp).
#include <string>

#include "judge/compare.hpp"

namespace stepbench {

std::string format_text(const comparison& c);
std::string format_markdown(const comparison& c);
// One line: "3 regressions, 1 improvement, ..." as the summary says it.
std::string summary_line(const comparison& c);

}  // namespace stepbench

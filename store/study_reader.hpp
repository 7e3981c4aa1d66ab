#pragma once
// Reading a study file (docs/study-format.md) back into the one model the run fills
// (study/study.hpp), for the commands that answer from a file (advise, compare, ratios).
// Every required attribute and field is checked: a file that lacks one is an error
// naming it, never a silent fallback to a constant.
#include <string>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// The oldest format this build reads (it writes study_format_version, the newest).
inline constexpr long study_format_read_min = 3;

// Reads the sweep's rows of the whole file: each problem's facts, truth outcome and
// methods (info, fit, rows by the writer's own column map), /stability's limits, and the
// root attributes in `record`. Throws std::runtime_error with one line, "cannot read study
// file '<path>': <what is wrong>", for a missing, non-HDF5, truncated, corrupt or foreign
// file, a format_version this build does not read, or a missing attribute or field.
study read_study(const std::string& path);
// Several files, checked at once (one process each); the first that cannot be read, in
// the order given, throws as read_study does.
std::vector<study> read_studies(const std::vector<std::string>& paths);

}  // namespace stepbench

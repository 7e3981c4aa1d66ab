#pragma once
// Reading a study file (docs/study-format.md) back, for the commands that answer from
// it (advise, compare, ratios). Every required attribute and field is checked: a file
// that lacks one is an error naming it, never a silent fallback to a constant.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/work_precision.hpp"
#include "study/study_data.hpp"

namespace stepbench {

// The newest format this build reads (and writes), and the oldest.
inline constexpr long study_format_read_min = 3;

// Reads the whole file. Throws std::runtime_error with one line, "cannot read study file
// '<path>': <what is wrong>", for a missing, non-HDF5, truncated, corrupt or foreign
// file, a format_version this build does not read, or a missing attribute or field.
study_data read_study(const std::string& path);
// Several files, read at once (one process each); the first that cannot be read, in the
// order given, throws as read_study does.
std::vector<study_data> read_studies(const std::vector<std::string>& paths);

}  // namespace stepbench

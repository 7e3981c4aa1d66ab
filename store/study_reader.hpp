#pragma once
// Reading a study file (docs/study-format.md) back into the one model the run fills
// (study/study.hpp), safely: a damaged file never reaches HDF5 in the calling process.
// What is read of each part is the part's own (parts/part.hpp `read`); parts/study.hpp
// read_study reads every part through this.
#include <functional>
#include <string>
#include <vector>

#include "store/h5.hpp"
#include "study/study.hpp"

namespace stepbench {

// The oldest format this build reads (it writes study_format_version, the newest).
inline constexpr long study_format_read_min = 3;

// Reads the parts' groups under the file's root into the study.
using study_parts_reader = std::function<void(const H5::Group& root, study&)>;

// Reads each file: its root attributes into `record` (a format_version this build reads,
// `timing`), then its parts with `read_parts`. Throws std::runtime_error with one line,
// "cannot read study file '<path>': <what is wrong>", for a missing, non-HDF5, truncated,
// corrupt or foreign file, a format this build does not read, or a missing group,
// attribute or field; for several files, the first in the order given that cannot be
// read. The files are checked at once, one process each.
std::vector<study> read_studies(const std::vector<std::string>& paths, const study_parts_reader& read_parts);

}  // namespace stepbench

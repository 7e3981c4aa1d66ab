#pragma once
// The study file (HDF5): the public format users script against. Layout documented in
// docs/study-format.md; bump study_format_version when it changes incompatibly.
#include <string>

#include "core/sweep.hpp"

namespace stepbench {

inline constexpr int study_format_version = 1;

// Throws std::runtime_error ("cannot write results file '<path>': <reason>") when the
// path cannot be created; leaves nothing behind. Call before a long run.
void check_writable(const std::string& path);

// Writes the study to a temporary file beside `path` and renames it into place, so an
// existing file is replaced whole or not at all.
void write_study(const study& s, const std::string& path);

// "Intel(R) Xeon(R) ..." from /proc/cpuinfo, or "unknown".
std::string cpu_model();
std::string utc_now_iso8601();

}  // namespace stepbench

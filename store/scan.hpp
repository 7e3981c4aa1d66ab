#pragma once
// /scan of a study file: written, and read back (`advise --scan`, merge).
#include <string>
#include <vector>

#include "store/h5.hpp"
#include "study/scan.hpp"

namespace stepbench {

// Reads /scan/<name> of a study file (name "" : the only scan in it); throws
// std::runtime_error naming the file and what is wrong, std::invalid_argument for a
// name it does not hold (listing those it does).
scan_result read_scan(const std::string& path, const std::string& name);

// Every scan of a study file, and the build that wrote it (format_version, git_commit,
// build_type, build_flags as one line), for `stepbench merge`; errors as read_scan's.
std::vector<scan_result> read_scans(const std::string& path);

std::string file_build(const std::string& path);

// /scan/<name> of each scan (docs/study-format.md).
void write_scans(H5::Group& root, const std::vector<scan_result>& scans);

// Joins shards of one scan (the same problem, axes, rates, substeps, methods, tolerance,
// fixed parameters, reference tolerances and work budget) into one scan, points in grid
// order; throws std::invalid_argument naming the first difference and the two values, a
// point two shards hold, or, unless `partial`, the points none holds. `missing` receives
// the grid indices no shard holds. A shard may hold no point (N above the grid's points).
scan_result merge_scans(const std::vector<scan_result>& shards, bool partial, std::vector<std::size_t>& missing);

}  // namespace stepbench

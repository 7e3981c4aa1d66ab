#pragma once
// /scan of a study file: written, and read back (`advise --scan`, merge).
#include <string>
#include <vector>

#include "store/h5.hpp"
#include "study/scan.hpp"

namespace stepbench {

// Every scan of a file (/scan), read as every study file is (store/study_reader.hpp: a
// damaged file never reaches HDF5 in the calling process); throws std::runtime_error,
// "cannot read study file '<path>': <what is wrong>". read_scan: /scan/<name> (name "" :
// the only scan in it), and std::invalid_argument for a name the file does not hold
// (listing those it does).
std::vector<scan_result> read_scans(const std::string& path);
scan_result read_scan(const std::string& path, const std::string& name);

// The build that wrote a study file (format_version, git_commit, build_type, build_flags,
// compiler and dependencies as one line), for `stepbench merge`'s check that its shards
// are of one build; errors as read_scan's, and a missing attribute is one.
std::string file_build(const std::string& path);

// /scan/<name> of each scan (docs/study-format.md).
void write_scans(H5::Group& root, const std::vector<scan_result>& scans);
// A scan's tables: its grid points, every run, and the cheapest run at each point and rate,
// in the schema's order (store/schema.cpp).
std::vector<schema::table> scan_tables();

// Joins shards of one scan (the same problem, axes, rates, substeps, methods, tolerance,
// fixed parameters, reference tolerances and work budget) into one scan, points in grid
// order; throws std::invalid_argument naming the first difference and the two values, a
// point two shards hold, or, unless `partial`, the points none holds. `missing` receives
// the grid indices no shard holds. A shard may hold no point (N above the grid's points).
scan_result merge_scans(const std::vector<scan_result>& shards, bool partial, std::vector<std::size_t>& missing);

}  // namespace stepbench

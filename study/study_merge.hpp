#pragma once
// Joining the shards of a study (`stepbench sweep --shard K/N`, `stepbench_bench
// --shard=K/N`; issue 20) into the study file an unsharded run writes. Each part of a
// study belongs to one problem (its /problems, /substeps, /frame_rates, /energy and /loop
// groups, its scans, the challenge with n_pendulum) and is copied whole from the shard that
// ran the problem; /stability, the same in every shard, from the first; the /verdict tables,
// a row per problem, are joined in the study's problem order, and the findings, which span
// problems, are generated again from the joined file by the code that wrote them
// (study/verdict.hpp). A timed study keeps the machine of each problem on /problems/<p>.
#include <string>
#include <utility>
#include <vector>

namespace stepbench {

// True when the file is a study written by a sweep (it has the root attribute `selection`);
// false for a file of scans alone (`stepbench scan`, a merge of scan shards). Throws
// std::runtime_error for a file that cannot be read.
bool is_study_file(const std::string& path);

struct study_merge_result {
  std::vector<std::string> problems;  // the problems merged, in the study's order
  std::vector<std::string> missing;   // selected problems no shard holds (merged with `partial`)
  // The machines (CPU model and cores) and the problems each ran, when the shards ran on
  // more than one; empty otherwise.
  std::vector<std::pair<std::string, std::vector<std::string>>> machines;
  double wall_seconds = 0.0;  // the sum of the shards'
};

// Merges the study shards at `paths` (one build: the caller checks file_build) into `out`,
// written whole or not at all. Throws std::invalid_argument, one line, naming: shards that
// differ in their selection, shard count, options (the first line of `sweep_options` that
// differs, both values) or timing settings; a shard given twice; a problem in two shards;
// selected problems no shard holds, unless `partial`.
study_merge_result merge_studies(const std::vector<std::string>& paths, const std::string& out, bool partial);

}  // namespace stepbench

#pragma once
// Joining the shards of a study (`stepbench sweep --shard K/N`, `stepbench_bench
// --shard=K/N`; issue 20) into the study file an unsharded run writes. Each part of a
// study belongs to one problem (its /problems, /substeps, /frame_rates, /energy and /loop
// groups, its scans, the challenge with n_pendulum) and is copied whole from the shard that
// ran the problem; /stability, the same in every shard, from the first; the /verdict tables,
// a row per problem, are joined in the study's problem order, and the findings, which span
// problems, are generated again from the joined file by the code that wrote them
// (study/verdict.hpp). A timed study keeps the machine of each problem on /problems/<p>.
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace stepbench {

// True when the file is a study written by a sweep (it has the root attribute `selection`);
// false for a file of scans alone (`stepbench scan`, a merge of scan shards). Throws
// std::runtime_error for a file that cannot be read.
bool is_study_file(const std::string& path);

// The shards of a study that a file holds, 0-based, of `count`: a shard's own (root
// attributes `shard_index` of `shard_count`), a partial merge's the shards it was merged
// from (`merged_shards` of `merged_shard_count`), 0 of 1 for an unsharded study or a whole
// merge. Throws std::runtime_error ("cannot read study shard '<path>': ...").
struct held_shards {
  std::vector<long> indices;  // ascending
  long count = 1;
  std::size_t problems = 0;  // the problems the file holds
};
held_shards held_shards_of(const std::string& path);

struct study_merge_result {
  std::vector<std::string> problems;  // the problems merged, in the study's order
  std::vector<std::string> missing;   // selected problems no shard holds (merged with `partial`)
  // The machines (CPU model and cores) and the problems each ran, when the shards ran on
  // more than one; empty otherwise.
  std::vector<std::pair<std::string, std::vector<std::string>>> machines;
  double wall_seconds = 0.0;  // the sum of the shards'
  std::size_t shards = 0;     // the shards merged (a partial merge given counts those it holds)
};

// Merges the study shards at `paths` (one build: the caller checks file_build) into `out`,
// written whole or not at all. Throws std::invalid_argument, one line, naming: shards that
// differ in their selection, shard count, options (the first line of `sweep_options` that
// differs, both values) or timing settings; a shard given twice; a problem in two shards;
// selected problems no shard holds, unless `partial`. A partial merge records the shards it
// holds (`merged_shards`), so a later merge with the missing shards completes the study.
// `before_write`, when given, runs once the merge is checked and built, before anything
// is written: what it throws leaves `out` as it was.
study_merge_result merge_studies(const std::vector<std::string>& paths, const std::string& out, bool partial,
                                 const std::function<void()>& before_write = {});

}  // namespace stepbench

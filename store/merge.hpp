#pragma once
// Joining the shards of a study (`stepbench sweep --shard K/N`, `stepbench_bench
// --shard=K/N`; issue 20) into the study file an unsharded run writes. Each part of the
// study (parts/part.hpp) names its group of the file and how its shards hold it (its
// merge_rule); merge walks that list in the study's order. A timed study keeps the
// machine of each problem on /problems/<p>.
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "store/schema.hpp"

namespace H5 {
class Group;
}

namespace stepbench {

// How the shards of a study hold a part's group, and so how merge joins it.
enum class merge_rule {
  per_problem,          // a child a problem, copied from the shard that ran the problem
  same_in_every_shard,  // computed from the build, not the problems: the first shard's
  in_one_shard,         // each child (a scan, a table of the challenge) from the one shard that holds it
  judged_again,         // its tables (a row a problem) joined in the study's order, then judged again
};

// A part's group of the study file, as merge joins it.
struct merged_group {
  std::string_view name;  // under the root: "problems", "stability", "scan", "verdict", ...
  merge_rule rule = merge_rule::per_problem;
  // judged_again: what spans the problems, judged again on the merged file (`root`,
  // every group joined) for the problems it holds, in the study's order.
  void (*judge_again)(H5::Group& root, const std::vector<std::string>& problems) = nullptr;
  // judged_again: its tables beyond store/schema.cpp's (the part's own).
  std::span<const schema::table> tables = {};
};

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
// `groups` are the study's parts' groups in its order (parts/study.hpp merged_groups).
study_merge_result merge_studies(const std::vector<std::string>& paths, const std::string& out, bool partial,
                                 const std::vector<merged_group>& groups,
                                 const std::function<void()>& before_write = {});

}  // namespace stepbench

#pragma once
// One shape for every analysis of the study (a "part"): the sweep's rows, the stability
// limits, substeps, frame rates, the game loop, long-run energy, the scans, the pendulum
// challenge and the verdict are each a row of one table (parts/registry.cpp), declared
// once with what the study does with it:
//
//   name      the part's name in `--parts`, `stepbench list` and the file's `parts`
//   describe  its settings, as lines of the file's `sweep_options` (merge joins only
//             shards whose options agree)
//   run       measures it into the study, after the parts above it
//   judge     derives its answers from the study as measured (and timed): run again by
//             stepbench_bench after it times the rows, and by merge on the joined study
//   write     its groups of the study file
//   read      its groups read back into the study, for the commands that answer from a
//             file (advise, compare, ratios): the model the run fills, filled again
//   merge     how the shards of a study hold it (merge_rule)
//
// Run, judge, write and read follow the table's order; describe and merge read the same table;
// the report orders its sections by the `parts` the file names. Adding an analysis is
// one file of parts/ that defines its study_part (its result type is its own: the study
// keeps it in `results`, keyed by that type) and one line of parts/registry.cpp;
// docs/architecture.md walks through one (parts/work_per_step.cpp).
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "store/merge.hpp"
#include "store/schema.hpp"
#include "study/study.hpp"

namespace H5 {
class Group;
}

namespace stepbench {

// What a part's run gets besides the study: the problems of this run (the selection, or
// its shard's share), and where its progress and warnings go.
struct part_context {
  std::vector<std::string> problems;
  bool progress = false;
  std::function<void(const std::string&)> say;  // one line, to stderr or around a live progress line
  std::function<void()> step_done;              // the sweep's, after each problem (a unit of progress)
};

struct study_part {
  std::string_view name;
  std::string_view summary;                    // what it answers, one line (`stepbench list --parts`)
  std::string_view group = {};                 // its group under the file's root when not its name ("problems")
  merge_rule merge = merge_rule::per_problem;  // how the shards of a study hold it (store/merge.hpp)
  // Its rows are cases stepbench_bench times (bench/cases.cpp): a listing of the cases
  // (--benchmark_list_tests) runs only the parts that have them.
  bool has_timed_cases = false;
  // Its progress advances once a problem (part_context::step_done), not once a run.
  bool progress_per_problem = false;
  // judged_again: what spans problems, judged again on the merged file.
  void (*judge_again)(H5::Group& root, const std::vector<std::string>& problems) = nullptr;
  // The tables it writes that no column map of store/ declares: a part's own, declared in
  // its file (`stepbench schema` lists them; merge joins a judged_again part's by them).
  std::span<const schema::table> tables = {};
  std::string (*describe)(const sweep_options&) = nullptr;
  void (*run)(study&, const part_context&) = nullptr;
  void (*judge)(study&) = nullptr;  // nullptr: nothing to judge
  void (*write)(H5::Group& root, const study&) = nullptr;
  // Called only when the file has its group; nullptr: no command reads it back.
  void (*read)(const H5::Group& root, study&) = nullptr;
  std::string_view group_name() const { return group.empty() ? name : group; }
};

// A part's write of its result `T` (when the study holds one) by `write(root, result)`:
// `.write = write_result<energy_study, write_energy>`.
template <class T, auto write>
void write_result(H5::Group& root, const study& s) {
  if (const T* r = s.results.find<T>()) write(root, *r);
}

// A list of names as a describe line shows it: "a,b,c", or "all" when empty.
std::string list_or_all(const std::vector<std::string>& names);

// Every part, in the study's order.
const std::vector<study_part>& study_parts();
// Their groups of the study file and how merge joins each, in the same order.
std::vector<merged_group> merged_groups();
// The tables the parts declare in their own files (study_part::tables), in their order.
std::vector<const schema::table*> parts_tables();
// Throws std::invalid_argument naming the unknown part and the known ones.
const study_part& find_part(std::string_view name);
// The parts `opts` selects (opts.parts, or every part), in the study's order.
std::vector<const study_part*> selected_parts(const sweep_options& opts);

// A preset is a selection of parts with the settings that go with it: `full` (every part
// at its defaults: the default study), `quick` (the CI study: 8 levels, every other
// tolerance, the stiff spring's quick scan, every part but the challenge).
struct study_preset {
  std::string_view name, summary;
  void (*apply)(sweep_options&);
};
const std::vector<study_preset>& study_presets();
const study_preset& find_preset(std::string_view name);

}  // namespace stepbench

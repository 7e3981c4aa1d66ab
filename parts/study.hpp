#pragma once
// The study as one run of its parts (parts/part.hpp): run, judge and write walk the one
// table of parts in its order.
#include <string>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// Checks the options (validate) and the parts they name, then runs the selected parts in
// the study's order on this run's problems (the selection, or its shard's share), then
// judges them.
study run_sweep(const sweep_options& opts);

// Judges every part that judges (the verdict): after the runs, and again once
// stepbench_bench has timed the rows.
void judge_study(study& s);

// The options that shape a study, one `name: value` line each: the parts run, then each
// part's describe lines (levels, ladders, tolerances, work budget, methods, --set
// overrides, the substeps, frame-rate, loop, energy, scan and challenge settings; not the
// shard). Written to the study file (root attribute `sweep_options`) so that `stepbench
// merge` joins only shards of one study.
std::string describe_options(const sweep_options& opts);

// The units of progress on_progress counts: the problems of this run, then one a part
// after the sweep.
std::size_t sweep_parts(const sweep_options& opts);

// Writes the study: the root attributes, then every part that holds results, in the
// study's order, atomically (store/study_file.hpp write_study_file).
void write_study(const study& s, const std::string& path);

// Reads study files back into the model the run fills: the root attributes (`record`),
// then every part that reads, in the study's order, from the groups the file has
// (store/study_reader.hpp says how a damaged file is refused, in one line).
std::vector<study> read_studies(const std::vector<std::string>& paths);
study read_study(const std::string& path);

}  // namespace stepbench

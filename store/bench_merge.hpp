#pragma once
// Joining the Google Benchmark JSON of a timed study's shards (`stepbench_bench
// --shard=K/N --benchmark_out=B.json --benchmark_out_format=json`, or the bench.json a
// study run writes beside its study), as `stepbench merge --bench` does, into one file
// that Google Benchmark's compare.py reads as one run's: every shard's benchmarks in shard
// order, each naming its shard (`stepbench_shard`, "K/N"), their family_index renumbered
// so that no two shards share one (compare.py sorts by it); the context the lowest
// shard's, with every shard's own context (host, CPUs, MHz, caches, date, ...) in the
// array `stepbench_shards`, so that no machine is lost. A merged file names the shards it
// holds, as a shard's names its own, so a partial merge is completed by merging it with
// the shards it lacks.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace stepbench {

// The context key stepbench_bench adds to a shard's JSON ("K/N") and that every benchmark
// of a merged file carries; the merged context's array of the shards' contexts.
inline constexpr const char* bench_shard_key = "stepbench_shard";
inline constexpr const char* bench_shards_key = "stepbench_shards";

// Benchmarks of the machine, not of a problem: the STREAM triad (bench/scaling.cpp), which
// every shard with a scaling family runs. Each shard's runs are kept (each row names its
// shard, so its machine), where any other name in two shards is an overlap.
inline constexpr std::string_view stream_triad_benchmark = "stream/triad";
inline constexpr std::string_view machine_benchmarks[] = {stream_triad_benchmark};

struct bench_join_result {
  std::string text;            // the joined JSON
  std::size_t benchmarks = 0;  // its rows
  std::size_t shards = 0;      // the shards joined
};

// Joins `paths`, one file for each study file in `study_paths`, in the same order: the
// i-th is the JSON of the i-th study file's shards. A file that names its shards (a
// shard's context `stepbench_shard`, a merged file's `stepbench_shards`) must name its
// study file's; one that names none (an older stepbench_bench's) is taken to be its
// study file's. An empty file is the JSON of a shard that timed nothing (Google Benchmark
// writes nothing then): accepted for a study shard that holds no problem. Throws
// std::invalid_argument, one line: a count of files other than the study files', a file
// of other shards than its study file's, a shard in two files, a benchmark name in two
// shards (but the machine's own); std::runtime_error ("cannot read '<path>': ...") for a
// file that is not Google Benchmark's JSON, and as held_shards_of for a study file.
bench_join_result join_bench_json(const std::vector<std::string>& paths, const std::vector<std::string>& study_paths);

}  // namespace stepbench

// `stepbench merge`: joins the shards of a study run with `sweep --shard K/N` or
// `stepbench_bench --shard=K/N` (parts/merge.hpp merge_studies), or of scans run with
// `scan --shard K/N` (study/scan.hpp merge_scans), on one machine or many, into one file;
// with --bench, the timed shards' Google Benchmark JSON too (store/bench_merge.hpp).
#include "store/merge.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <map>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "parts/part.hpp"
#include "parts/study.hpp"
#include "store/bench_merge.hpp"
#include "store/bounded_child.hpp"
#include "store/scan.hpp"
#include "store/study_file.hpp"
#include "study/scan.hpp"

namespace stepbench::cli {
namespace {

struct merge_args {
  std::vector<std::string> inputs;
  std::string out;
  bool partial = false;
  std::vector<std::string> bench;  // each study file's Google Benchmark JSON, in the same order
  std::string bench_out;
};

int run_study_merge(const merge_args& a) {
  // The benchmark JSON is joined once the study merge is checked and built, and written
  // after the study (as stepbench_bench writes them): a refusal writes neither.
  bench_join_result joined;
  const auto r = merge_studies(a.inputs, a.out, a.partial, merged_groups(), [&] {
    if (a.bench.empty()) return;
    joined = join_bench_json(a.bench, a.inputs);
    check_writable(a.bench_out);
  });
  if (!a.bench.empty()) write_image(std::vector<unsigned char>(joined.text.begin(), joined.text.end()), a.bench_out);
  if (!r.missing.empty())
    fmt::print(stderr, "merge: {} of the {} selected problems {} in no shard (--partial): {}\n", r.missing.size(),
               r.missing.size() + r.problems.size(), r.missing.size() == 1 ? "is" : "are", fmt::join(r.missing, ", "));
  if (!r.machines.empty()) {
    std::vector<std::string> parts;
    for (const auto& [machine, problems] : r.machines)
      parts.push_back(fmt::format("{}: {}", machine, fmt::join(problems, ", ")));
    fmt::print(stderr,
               "merge: the shards ran on {} machines ({}); each problem records its machine (/problems/<p> cpu), and "
               "timings are compared only within a problem\n",
               r.machines.size(), fmt::join(parts, "; "));
  }
  fmt::print(stderr, "merge: {} of {} from {}\n", count_of(r.problems.size(), "problem"),
             r.problems.size() + r.missing.size(), count_of(r.shards, "shard"));
  if (!a.bench.empty())
    fmt::print(stderr, "merge: {} of {} into {}\n", count_of(joined.benchmarks, "benchmark"),
               count_of(joined.shards, "shard"), a.bench_out);
  fmt::print(stderr, "wrote {}{}\n", a.out, a.bench.empty() ? "" : " and " + a.bench_out);
  return 0;
}

int run_merge(const merge_args& a) {
  if (a.inputs.size() < 2) throw std::invalid_argument("merge: give at least two shard files");
  for (std::size_t i = 0; i < a.inputs.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (a.inputs[i] == a.inputs[j])
        throw std::invalid_argument(fmt::format("merge: '{}' is named twice (overlapping shards)", a.inputs[i]));
  // No output may be one of the inputs (merging would overwrite a shard), nor both one file.
  const auto same = [](const std::string& x, const std::string& y) {
    std::error_code ec;
    return x == y || std::filesystem::equivalent(x, y, ec);
  };
  std::vector<std::string> outputs{a.out};
  if (!a.bench_out.empty()) outputs.push_back(a.bench_out);
  for (const auto& out : outputs)
    for (const auto* paths : {&a.inputs, &a.bench})
      for (const auto& path : *paths)
        if (same(path, out))
          throw std::invalid_argument(
              fmt::format("merge: the output '{}' is one of the shards; name another file", out));
  if (outputs.size() == 2 && same(a.out, a.bench_out))
    throw std::invalid_argument(fmt::format("merge: -o and --bench-out both name '{}'; name two files", a.out));
  for (std::size_t i = 0; i < a.bench.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (a.bench[i] == a.bench[j])
        throw std::invalid_argument(fmt::format("merge: '{}' is named twice (overlapping shards)", a.bench[i]));
  // One build: shards of different builds, formats or flags are not one study.
  const std::string build = file_build(a.inputs.front());
  for (std::size_t i = 1; i < a.inputs.size(); ++i)
    if (const std::string b = file_build(a.inputs[i]); b != build)
      throw std::invalid_argument(fmt::format("merge: '{}' was written by another build ({}) than '{}' ({})",
                                              a.inputs[i], b, a.inputs.front(), build));
  // Study shards (written by a sweep) or scan shards, not both.
  const bool study_shards = is_study_file(a.inputs[0]);
  for (std::size_t i = 1; i < a.inputs.size(); ++i)
    if (is_study_file(a.inputs[i]) != study_shards)
      throw std::invalid_argument(fmt::format("merge: '{}' is a {} and '{}' a {}; merge joins shards of one kind",
                                              a.inputs[0], study_shards ? "study shard" : "scan file", a.inputs[i],
                                              study_shards ? "scan file" : "study shard"));
  if (study_shards) return run_study_merge(a);
  if (!a.bench.empty())
    throw std::invalid_argument("merge: --bench joins the benchmark JSON of timed study shards; these are scan files");
  std::map<std::string, std::vector<scan_result>> by_name;
  for (const auto& path : a.inputs)
    for (auto& s : read_scans(path)) by_name[s.options.name].push_back(std::move(s));
  check_writable(a.out);
  study merged;
  merged.options.parts = {"scans"};
  auto& scans = merged.results.put(std::vector<scan_result>{});
  for (auto& [name, shards] : by_name) {
    std::vector<std::size_t> missing;
    scans.push_back(merge_scans(shards, a.partial, missing));
    scans.back().options.name = name;
    if (!missing.empty())
      fmt::print(stderr, "merge: scan '{}' lacks {} of {} grid points (--partial): {}{}\n", name, missing.size(),
                 scans.back().grid_points,
                 fmt::join(missing.begin(), missing.begin() + std::min<std::size_t>(missing.size(), 10), ", "),
                 missing.size() > 10 ? ", ..." : "");
    merged.wall_seconds += scans.back().wall_seconds;
  }
  judge_study(merged);
  write_study(merged, a.out);
  for (const auto& s : scans)
    fmt::print(stderr, "merge: /scan/{}: {} of {} points from {}\n", s.options.name, s.points.size(), s.grid_points,
               count_of(by_name[s.options.name].size(), "shard"));
  fmt::print(stderr, "wrote {}\n", a.out);
  return 0;
}

}  // namespace

// The merge in a child process (store/bounded_child.hpp): merge opens the shards with
// HDF5 and copies their groups whole, where a damaged shard crashed it (79 of 150 damaged
// copies of a shard, before this). The files it writes are written whole by the child or
// not at all; a child that crashes or loops is named in one line, with the shard the
// readers find damaged when they find one.
int run_merge_isolated(const merge_args& a) {
  std::size_t bytes = 0;
  for (const auto* paths : {&a.inputs, &a.bench})
    for (const auto& path : *paths) {
      std::error_code ec;
      if (const auto size = std::filesystem::file_size(path, ec); !ec) bytes += size;
    }
  // A merge of the default study's shards takes about a second; the memory bound is the
  // readers'.
  constexpr long merge_cpu_seconds = 60;
  return run_in_bounded_child(
      [&] { return run_merge(a); }, merge_cpu_seconds, child_memory_bound(bytes), "merging them",
      [&](const std::string& end) {
        read_studies(a.inputs);  // throws naming the first shard it cannot read
        throw std::runtime_error(fmt::format("merge: the shards {}: {}", fmt::join(a.inputs, ", "), end));
      });
}

command add_merge(CLI::App& app) {
  auto a = std::make_shared<merge_args>();
  auto* sub = app.add_subcommand(
      "merge",
      "join the shard files of a study (`sweep --shard K/N`, `stepbench_bench --shard=K/N`) or of scans "
      "(`scan --shard K/N`) into one file");
  sub->add_option("inputs", a->inputs, "the shard files")->required();
  sub->add_option("-o,--out", a->out, "the merged file")->required();
  sub->add_flag("--partial", a->partial, "merge even when some problems (or grid points) are in no shard (says which)");
  auto* bench = sub->add_option("--bench", a->bench,
                                "the Google Benchmark JSON of each timed study shard (`stepbench_bench "
                                "--benchmark_out=F --benchmark_out_format=json`, or the bench.json beside its study), "
                                "one for each shard file and in the same order, after the shard files");
  auto* bench_out = sub->add_option("--bench-out", a->bench_out,
                                    "the joined benchmark JSON (compare.py reads it): the shards' benchmarks in shard "
                                    "order, each naming its shard, and every shard's context (its machine)");
  bench->needs(bench_out);
  bench_out->needs(bench);
  sub->footer(
      "exit codes: 0 merged; 1 a file unreadable or unwritable; 2 shards that overlap, miss problems or points "
      "(without --partial), differ in build, format or options, or mix study and scan shards; benchmark JSON files "
      "not one for each shard file, of other shards than theirs, or with a benchmark in two shards\n");
  return {sub, [a] { return run_merge_isolated(*a); }};
}

}  // namespace stepbench::cli

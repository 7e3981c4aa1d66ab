// `stepbench merge`: joins the shards of scans run with `scan --shard K/N` on one machine
// or many (study/scan.hpp merge_scans) into one study file.
#include <fmt/format.h>

#include <map>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "study/scan.hpp"
#include "study/study_file.hpp"

namespace stepbench::cli {
namespace {

struct merge_args {
  std::vector<std::string> inputs;
  std::string out;
  bool partial = false;
};

int run_merge(const merge_args& a) {
  if (a.inputs.size() < 2) throw std::invalid_argument("merge: give at least two shard files");
  for (std::size_t i = 0; i < a.inputs.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (a.inputs[i] == a.inputs[j])
        throw std::invalid_argument(fmt::format("merge: '{}' is named twice (overlapping shards)", a.inputs[i]));
  // One build: shards of different builds, formats or flags are not one study.
  const std::string build = file_build(a.inputs.front());
  for (const auto& path : a.inputs)
    if (const std::string b = file_build(path); b != build)
      throw std::invalid_argument(fmt::format("merge: '{}' was written by another build ({}) than '{}' ({})", path, b,
                                              a.inputs.front(), build));
  std::map<std::string, std::vector<scan_result>> by_name;
  for (const auto& path : a.inputs)
    for (auto& s : read_scans(path)) by_name[s.options.name].push_back(std::move(s));
  check_writable(a.out);
  study merged;
  for (auto& [name, shards] : by_name) {
    std::vector<std::size_t> missing;
    merged.scans.push_back(merge_scans(shards, a.partial, missing));
    merged.scans.back().options.name = name;
    if (!missing.empty())
      fmt::print(stderr, "merge: scan '{}' lacks {} of {} grid points (--partial): {}{}\n", name, missing.size(),
                 merged.scans.back().grid_points,
                 fmt::join(missing.begin(), missing.begin() + std::min<std::size_t>(missing.size(), 10), ", "),
                 missing.size() > 10 ? ", ..." : "");
    merged.wall_seconds += merged.scans.back().wall_seconds;
  }
  write_study(merged, a.out);
  for (const auto& s : merged.scans)
    fmt::print(stderr, "merge: /scan/{}: {} of {} points from {}\n", s.options.name, s.points.size(), s.grid_points,
               count_of(static_cast<long long>(by_name[s.options.name].size()), "shard"));
  fmt::print(stderr, "wrote {}\n", a.out);
  return 0;
}

}  // namespace

command add_merge(CLI::App& app) {
  auto a = std::make_shared<merge_args>();
  auto* sub = app.add_subcommand("merge", "join the shard files of scans run with `scan --shard K/N` into one file");
  sub->add_option("inputs", a->inputs, "the shard files")->required();
  sub->add_option("-o,--out", a->out, "the merged file")->required();
  sub->add_flag("--partial", a->partial, "merge even when some grid points are in no shard (says which)");
  sub->footer(
      "exit codes: 0 merged; 1 a file unreadable or unwritable; 2 shards that overlap, miss points (without "
      "--partial), or differ in build, format or scan options\n");
  return {sub, [a] { return run_merge(*a); }};
}

}  // namespace stepbench::cli

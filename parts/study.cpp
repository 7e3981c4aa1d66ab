#include "parts/study.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cstdio>
#include <mutex>

#include "core/contains.hpp"
#include "parts/part.hpp"
#include "run/sweep.hpp"
#include "store/h5.hpp"
#include "store/study_file.hpp"
#include "store/study_reader.hpp"

namespace stepbench {

std::string describe_options(const sweep_options& opts) {
  std::vector<std::string> parts, lines;
  for (const auto* p : selected_parts(opts)) {
    parts.emplace_back(p->name);
    lines.push_back(p->describe(opts));
  }
  return fmt::format("parts: {}\n{}", fmt::join(parts, ","), fmt::join(lines, "\n"));
}

std::size_t sweep_parts(const sweep_options& opts) {
  std::size_t n = 0;
  for (const auto* p : selected_parts(opts)) n += p->progress_per_problem ? shard_problems(opts).size() : 1;
  return n;
}

study run_sweep(const sweep_options& opts) {
  validate(opts);
  const auto parts = selected_parts(opts);
  const auto start = std::chrono::steady_clock::now();
  study out;
  out.options = opts;
  out.swept = true;
  // Every part takes only this run's problems, so that the shards of a study hold every
  // part of it once. Progress and warnings reach the caller under one lock (the sweep's
  // problems run on threads).
  std::mutex callbacks;
  std::size_t done = 0;
  const std::size_t total = sweep_parts(opts);
  part_context ctx;
  ctx.problems = shard_problems(opts);
  ctx.progress = opts.progress;
  ctx.say = [&](const std::string& line) {
    std::lock_guard lock(callbacks);
    if (opts.on_warning)
      opts.on_warning(line);
    else
      std::fprintf(stderr, "%s\n", line.c_str());
  };
  ctx.step_done = [&] {
    std::lock_guard lock(callbacks);
    if (opts.on_progress) opts.on_progress(++done, total);
  };
  for (const auto* p : parts) {
    if (p->run) p->run(out, ctx);
    if (p->name != "sweep") ctx.step_done();
  }
  judge_study(out);
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void judge_study(study& s) {
  for (const auto& p : study_parts())
    if (p.judge && (s.options.parts.empty() || contains(s.options.parts, std::string(p.name)))) p.judge(s);
}

std::vector<study> read_studies(const std::vector<std::string>& paths) {
  return read_studies(paths, [](const H5::Group& root, study& s) {
    for (const auto& p : study_parts())
      if (p.read && h5::is_group(root, std::string(p.group_name()))) p.read(root, s);
  });
}

study read_study(const std::string& path) { return std::move(read_studies({path}).front()); }

void write_study(const study& s, const std::string& path) {
  write_study_file(path, [&](H5::H5File& file) {
    write_root_attributes(file, s, describe_options(s.options));
    std::vector<std::string> names;
    for (const auto* p : selected_parts(s.options)) names.emplace_back(p->name);
    h5::attr(file, "parts", fmt::format("{}", fmt::join(names, ",")));
    for (const auto& p : study_parts()) p.write(file, s);
  });
}

}  // namespace stepbench

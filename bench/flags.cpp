#include "bench/flags.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "cli/args.hpp"
#include "core/text.hpp"
#include "registry/scenes.hpp"

namespace stepbench::bench {

const char* own_flags_help() {
  return "stepbench_bench: Google Benchmark timing of the accuracy study: one case per completed row of the sweep,\n"
         "the scaling families spring_chain/<method>/masses:N and bouncing_balls/<method>/balls:N, and the\n"
         "memory-bandwidth triad stream/triad.\n"
         "\n"
         "Our flags:\n"
         "  --quick              CI mode: 8-level ladder, thinned tolerances, min time 0.002 s, 1 repetition\n"
         "  --study_out=PATH     write the study file (timings beside accuracy); results to bench.json beside it\n"
         "  --problem=NAME       sweep and time this problem only, and its scaling family (repeatable)\n"
         "  --scene=FILE         a scene file (docs/scenes.md): swept and timed as --problem=NAME (repeatable)\n"
         "  --parts=A,B          run only these parts of the study (`stepbench list` names them)\n"
         "  --plugin=PATH        load a plugin's methods into the study (repeatable; docs/plugins.md)\n"
         "  --isolate            run each accuracy run of a plugin's method in a child process\n"
         "  --shard=K/N          the timed study of shard K of N: the share of the problems `stepbench sweep\n"
         "                       --shard K/N` takes, timing only their cases (`stepbench merge` joins the shards)\n"
         "  --set=P.NAME=VALUE   a problem parameter, as stepbench's --set; NAME=VALUE with one --problem\n"
         "  --case_budget=S      cut a family's finer cases once one run would exceed S s (0.5; quick 0.05)\n"
         "  --strict             exit 3 when some case failed (recorded in the study; else exit 0)\n"
         "  --verbose            with --study_out: Google Benchmark's table and context on the terminal too\n"
         "\n"
         "With --study_out, stderr shows one progress line and stdout the verdict at the end; Google Benchmark's\n"
         "table goes to the terminal only with --verbose or --benchmark_format (the verdict then goes to stderr\n"
         "if stdout carries json or csv), and to --benchmark_out instead of bench.json when that is given.\n"
         "The scaling families and the triad ignore --set; the triad runs with either scaling family.\n"
         "Google Benchmark's context line \"***WARNING*** Library was built as DEBUG\" is left out (Debian\n"
         "builds libbenchmark without NDEBUG; bench.json records library_build_type); its other warnings stay.\n"
         "Exit: 0 done, 1 an error, 2 bad usage, 3 with --strict some case failed.\n"
         "\n"
         "Google Benchmark's flags:\n";
}

options take_own_flags(int& argc, char** argv, std::vector<std::string>& extra) {
  options o;
  bool min_time_given = false, reps_given = false, budget_given = false;
  int out = 1;
  std::vector<std::string> sets;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      o.quick = true;
    } else if (a == "--strict") {
      o.strict = true;
    } else if (a == "--verbose") {
      o.verbose = true;
    } else if (a.rfind("--set=", 0) == 0) {
      sets.push_back(a.substr(6));  // resolved below, once every --problem is known
    } else if (a.rfind("--problem=", 0) == 0) {
      o.problems.push_back(a.substr(10));  // checked by run_sweep's validate()
      if (o.problems.back().empty()) throw std::invalid_argument("--problem needs a problem name");
    } else if (a.rfind("--scene=", 0) == 0) {
      // A scene file (docs/scenes.md): read, checked and registered here, before any
      // --set names it, and swept and timed as --problem=NAME.
      if (a.size() == 8) throw std::invalid_argument("--scene needs a scene file");
      o.problems.push_back(load_scene(a.substr(8)));
    } else if (a.rfind("--parts=", 0) == 0) {
      for (const auto name : split(std::string_view(a).substr(8), ',')) {
        o.parts.emplace_back(name);  // checked by run_sweep's validate()
        if (name.empty()) throw std::invalid_argument("--parts needs part names: --parts=A,B");
      }
    } else if (a == "--isolate") {
      o.isolate = true;
    } else if (a.rfind("--plugin=", 0) == 0) {
      o.plugins.push_back(a.substr(9));  // loaded by main, before the sweep
      if (o.plugins.back().empty()) throw std::invalid_argument("--plugin needs a path");
    } else if (a.rfind("--shard=", 0) == 0) {
      parse_shard(a.substr(8), o.shard_index, o.shard_count);
    } else if (a == "--study_out" || a == "--case_budget" || a == "--set" || a == "--problem" || a == "--shard" ||
               a == "--parts" || a == "--plugin" || a == "--scene") {
      throw std::invalid_argument(a + " takes its value after '=': " + a + "=VALUE");
    } else if (a.rfind("--study_out=", 0) == 0) {
      o.study_out = a.substr(12);
      if (o.study_out.empty()) throw std::invalid_argument("--study_out needs a path");
    } else if (a.rfind("--case_budget=", 0) == 0) {
      o.case_budget_s = parse_number(a.substr(14), "--case_budget");
      if (!(o.case_budget_s > 0)) throw std::invalid_argument("--case_budget must be > 0");
      budget_given = true;
    } else {
      if (a.rfind("--benchmark_min_time=", 0) == 0) {
        min_time_given = true;
        o.min_time_s = parse_number(a.substr(21), "--benchmark_min_time");
      }
      if (a.rfind("--benchmark_repetitions=", 0) == 0) {
        reps_given = true;
        const double reps = parse_number(a.substr(24), "--benchmark_repetitions");
        if (!(reps >= 1 && reps <= 1000 && reps == std::floor(reps)))
          throw std::invalid_argument("--benchmark_repetitions must be a whole number from 1 to 1000");
        o.repetitions = static_cast<int>(reps);
      }
      if (a == "--benchmark_list_tests" || a == "--benchmark_list_tests=true") o.list_only = true;
      if (a.rfind("--benchmark_format=", 0) == 0) {
        // Checked here: Google Benchmark answers a bad value with its help and exit 0.
        o.benchmark_format = a.substr(19);
        if (o.benchmark_format != "console" && o.benchmark_format != "json" && o.benchmark_format != "csv")
          throw std::invalid_argument("--benchmark_format must be console, json or csv, got '" + o.benchmark_format +
                                      "'");
      }
      if (a.rfind("--benchmark_out=", 0) == 0) o.benchmark_out = a.substr(16);
      argv[out++] = argv[i];
    }
  }
  argc = out;
  for (const auto& text : sets) add_override(o.overrides, text, o.problems);
  if (o.quick) {
    if (!min_time_given) o.min_time_s = 0.002;
    if (!reps_given) o.repetitions = 1;
    if (!budget_given) o.case_budget_s = 0.05;
  }
  if (!min_time_given) extra.push_back(fmt::format("--benchmark_min_time={}", o.min_time_s));
  if (!reps_given) extra.push_back(fmt::format("--benchmark_repetitions={}", o.repetitions));
  return o;
}

}  // namespace stepbench::bench

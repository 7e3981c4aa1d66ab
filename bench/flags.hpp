#pragma once
// stepbench_bench's own flags, taken out of argv before Google Benchmark sees it. Their
// help (own_flags_help, printed by --help above Google Benchmark's) is the list below.
// Quick and full mode supply defaults for --benchmark_min_time and
// --benchmark_repetitions unless those are given.
#include <string>
#include <vector>

#include "cli/args.hpp"

namespace stepbench::bench {

struct options {
  bool quick = false, strict = false, verbose = false;
  std::string study_out;
  double case_budget_s = 0.5;
  double min_time_s = 0.01;
  // Two repetitions: a spread for compare's noise threshold, and the full study (3348
  // cases) within 3 minutes on the 2-core machine (three took 3 min 39 s).
  int repetitions = 2;
  bool list_only = false;
  parameter_overrides overrides;
  // --problem=NAME (repeatable): sweep and time only these problems (the study file then
  // holds only them), and register the scaling families only of those problems; empty:
  // every problem. A narrow --benchmark_filter still sweeps every selected problem, since
  // the cases are the sweep's rows.
  std::vector<std::string> problems;
  // --parts=A,B (repeatable): run only these parts of the study (parts/part.hpp); empty:
  // the preset's (every part, or --quick's).
  std::vector<std::string> parts;
  // --plugin=PATH (repeatable): plugins whose methods join the study (docs/plugins.md).
  std::vector<std::string> plugins;
  bool isolate = false;  // --isolate: each accuracy run of a plugin's method in a child process
  // --shard=K/N: shard_index K - 1 of shard_count N, as `stepbench sweep --shard K/N`.
  int shard_index = 0, shard_count = 1;
  // Google Benchmark's flags that decide where its results go, as given (empty: not given).
  std::string benchmark_format, benchmark_out;
};

// One line per flag of ours, for --help.
const char* own_flags_help();

// Removes our flags from argv (argc updated) and appends Google Benchmark flags for the
// mode's defaults to `extra`. Throws std::invalid_argument on a malformed flag.
options take_own_flags(int& argc, char** argv, std::vector<std::string>& extra);

}  // namespace stepbench::bench

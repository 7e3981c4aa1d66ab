#pragma once
// stepbench_bench's own flags, taken out of argv before Google Benchmark sees it:
//   --quick              short minimum time, 8-level ladder, thinned tolerances (CI)
//   --study_out=PATH     write the study file with each timing next to its accuracy row
//   --case_budget=S      cut a family's finer cases once one iteration would exceed S s
//   --strict             exit 3 when some case failed (a finding recorded in the study;
//                        by default the run that found it succeeded: exit 0)
//   --set=P.NAME=VALUE   a problem parameter, as every `stepbench` command's --set: a
//                        number or a name the parameter takes; NAME=VALUE alone with
//                        exactly one --problem (repeatable)
// Quick and full mode supply defaults for --benchmark_min_time and
// --benchmark_repetitions unless those are given.
#include <map>
#include <string>
#include <vector>

#include "cli/args.hpp"

namespace stepbench::bench {

struct options {
  bool quick = false;
  bool strict = false;
  std::string study_out;
  double case_budget_s = 0.5;
  double min_time_s = 0.01;
  // Two repetitions: a spread for compare's noise threshold, and the full study (3348
  // cases) within 3 minutes on the 2-core machine (three took 3 min 39 s).
  int repetitions = 2;
  bool list_only = false;
  parameter_overrides overrides;
  // --problem=NAME (repeatable): sweep and time only these problems (the study file then
  // holds only them); empty: every problem. A narrow --benchmark_filter still sweeps
  // every problem, since the cases are the sweep's rows.
  std::vector<std::string> problems;
};

// Removes our flags from argv (argc updated) and appends Google Benchmark flags for the
// mode's defaults to `extra`. Throws std::invalid_argument on a malformed flag.
options take_own_flags(int& argc, char** argv, std::vector<std::string>& extra);

}  // namespace stepbench::bench

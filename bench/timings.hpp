#pragma once
// The reporter between Google Benchmark and the study: it keeps each repetition's wall
// time per run for the case it was registered as, counts the cases done for the progress
// line, and forwards every report to
//  - the display reporter Google Benchmark makes from the user's flags
//    (benchmark::CreateDefaultDisplayReporter: every --benchmark_format and
//    --benchmark_counters_tabular as documented; stdout carries exactly that format), or
//    none when the results go only to a file (a study run without --verbose);
//  - a file reporter of our own (bench.json beside the study), or none.
// The context header goes to stderr through a filter: without the display, only Google
// Benchmark's warnings; never its "Library was built as DEBUG" line (Debian builds the
// library without NDEBUG; the JSON still records library_build_type), unless `verbose`.
#include <benchmark/benchmark.h>

#include "bench/cases.hpp"
#include "bench/progress.hpp"

namespace stepbench::bench {

class collecting_reporter : public benchmark::BenchmarkReporter {
 public:
  collecting_reporter(benchmark::BenchmarkReporter* display, benchmark::BenchmarkReporter* file, case_book& book,
                      progress_line& progress, bool verbose)
      : display_(display), file_(file), book_(book), progress_(progress), verbose_(verbose) {}
  bool ReportContext(const Context& context) override;
  void ReportRuns(const std::vector<Run>& runs) override;
  void Finalize() override;

  timing_settings machine;  // the context's: num_cpus, mhz_per_cpu, cpu_scaling_enabled

 private:
  benchmark::BenchmarkReporter* display_;
  benchmark::BenchmarkReporter* file_;
  case_book& book_;
  progress_line& progress_;
  bool verbose_;
};

}  // namespace stepbench::bench

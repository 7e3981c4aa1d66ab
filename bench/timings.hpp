#pragma once
// The reporter between Google Benchmark and the study: it forwards every report to the
// display reporter Google Benchmark makes from the user's flags
// (benchmark::CreateDefaultDisplayReporter: every --benchmark_format and
// --benchmark_counters_tabular as documented; stdout carries exactly that format) and
// keeps each repetition's wall time per run for the case it was registered as. Progress
// goes to stderr.
#include <benchmark/benchmark.h>

#include <chrono>

#include "bench/cases.hpp"

namespace stepbench::bench {

class collecting_reporter : public benchmark::BenchmarkReporter {
 public:
  collecting_reporter(benchmark::BenchmarkReporter* display, case_book& book) : display_(display), book_(book) {}
  bool ReportContext(const Context& context) override;
  void ReportRuns(const std::vector<Run>& runs) override;
  void Finalize() override { display_->Finalize(); }

  int cpu_scaling = -1;  // 1 on, 0 off, -1 unknown
  int num_cpus = 0;
  double mhz = 0.0;

 private:
  benchmark::BenchmarkReporter* display_;
  case_book& book_;
  std::size_t reported_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_progress_ = start_;
};

}  // namespace stepbench::bench

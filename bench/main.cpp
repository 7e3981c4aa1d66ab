// stepbench_bench: Google Benchmark timing of the study. It runs the accuracy sweep
// (every method, ours and the peers, over its ladder, measured by the same code as
// `stepbench sweep`), registers one timed case per completed row from the same entries,
// runs them, and writes the study file with each timing next to its accuracy row
// (--study_out). stdout carries exactly the output format chosen with
// --benchmark_format; progress and the summary go to stderr. The performance ratios
// and equal-error tables come from the study file: `stepbench ratios`.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "bench/cases.hpp"
#include "bench/flags.hpp"
#include "bench/scaling.hpp"
#include "bench/timings.hpp"
#include "study/study_file.hpp"
#include "study/sweep.hpp"

using namespace stepbench;

int main(int argc, char** argv) {
  try {
    std::vector<std::string> extra;
    bench::options opts = bench::take_own_flags(argc, argv, extra);
    std::vector<char*> args(argv, argv + argc);
    for (auto& e : extra) args.push_back(e.data());
    int n = static_cast<int>(args.size());
    args.push_back(nullptr);
    benchmark::Initialize(&n, args.data());
    if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
    if (!opts.study_out.empty() && !opts.list_only) check_writable(opts.study_out);

    // The accuracy sweep first: it gives each case its counters and the study its rows.
    sweep_options sopts;
    if (opts.quick) {
      sopts.levels = 8;
      sopts.tolerances = tolerance_ladder(true);
    }
    sopts.overrides = opts.overrides;  // checked by run_sweep's validate()
    sopts.problems = opts.problems;
    sopts.progress = !opts.list_only;
    const auto start = std::chrono::steady_clock::now();
    study s = run_sweep(sopts);
    bench::case_book book(opts.case_budget_s);
    book.register_all(s);
    bench::register_scaling();

    // The display reporter is made after Initialize, from the flags it parsed.
    bench::collecting_reporter reporter(benchmark::CreateDefaultDisplayReporter(), book);
    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::Shutdown();
    if (opts.list_only) return 0;

    if (!opts.study_out.empty() && !book.any_timed())
      throw std::runtime_error("no case was timed (does --benchmark_filter match any?); " + opts.study_out +
                               " was not written");
    book.merge_into_rows();
    timing_settings ts;
    ts.mode = opts.quick ? "quick" : "full";
    ts.min_time_s = opts.min_time_s;
    ts.repetitions = opts.repetitions;
    ts.case_budget_s = opts.case_budget_s;
    ts.num_cpus = reporter.num_cpus;
    ts.mhz_per_cpu = reporter.mhz;
    ts.cpu_scaling_enabled = reporter.cpu_scaling;
    ts.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    s.timed = ts;
    if (!opts.study_out.empty()) {
      write_study(s, opts.study_out);
      fmt::print(stderr,
                 "stepbench_bench: wrote {} ({} mode, {} cases timed) in {:.1f} s; `stepbench ratios --study {}` "
                 "prints the performance ratios\n",
                 opts.study_out, ts.mode, book.timed_count(), ts.wall_seconds, opts.study_out);
    } else {
      fmt::print(stderr, "stepbench_bench: timed {} cases in {:.1f} s ({} mode)\n", book.timed_count(), ts.wall_seconds,
                 ts.mode);
    }
    return report_study_outcome(s, "stepbench_bench", opts.strict);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "stepbench_bench: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stepbench_bench: error: %s\n", e.what());
    return 1;
  }
}

// stepbench_bench: Google Benchmark timing of the study. It runs the accuracy sweep
// (every method, ours and the peers, over its ladder, measured by the same code as
// `stepbench sweep`), registers one timed case per completed row from the same entries,
// runs them, and writes the study file with each timing next to its accuracy row
// (--study_out). A study run shows one progress line on stderr (bench/progress.hpp),
// writes Google Benchmark's results to bench.json beside the study (its JSON format, read
// by compare.py), and ends with the verdict on stdout. Otherwise, or with --verbose or
// --benchmark_format, stdout carries exactly the output format chosen with
// --benchmark_format; progress and the summary go to stderr. The performance ratios and
// equal-error tables come from the study file: `stepbench ratios`.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "bench/cases.hpp"
#include "bench/flags.hpp"
#include "bench/progress.hpp"
#include "bench/scaling.hpp"
#include "bench/timings.hpp"
#include "judge/outcome.hpp"
#include "parts/part.hpp"
#include "parts/study.hpp"
#include "registry/plugins.hpp"
#include "registry/registry.hpp"
#include "render/verdict.hpp"
#include "run/sweep.hpp"
#include "store/bench_merge.hpp"
#include "store/study_file.hpp"
#include "study/verdict.hpp"

using namespace stepbench;

namespace {

// A reporter that reports nothing: the listing below writes to its output stream.
class listing_reporter : public benchmark::BenchmarkReporter {
 public:
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>&) override {}
};

// The number of cases the run will time: Google Benchmark's own listing of what its
// filter selects, counted (--benchmark_list_tests on for the listing, off again after;
// every other flag stays as the first Initialize parsed it). The same selection as the
// run, without a second implementation of the filter.
std::size_t count_selected(char* program) {
  std::string on = "--benchmark_list_tests=true", off = "--benchmark_list_tests=false";
  char* list_args[] = {program, on.data(), nullptr};
  int list_argc = 2;
  benchmark::Initialize(&list_argc, list_args);
  std::ostringstream names, errors;
  listing_reporter listing;
  listing.SetOutputStream(&names);
  listing.SetErrorStream(&errors);  // "Failed to match any benchmarks": the run says it
  const std::size_t n = benchmark::RunSpecifiedBenchmarks(&listing);
  char* run_args[] = {program, off.data(), nullptr};
  int run_argc = 2;
  benchmark::Initialize(&run_argc, run_args);
  return n;
}

std::size_t run_count(const study& s) {
  std::size_t n = 0;
  for (const auto& ps : s.problems)
    for (const auto& ms : ps.methods) n += ms.rows.size();
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> extra;
    bench::options opts = bench::take_own_flags(argc, argv, extra);
    for (const auto& path : opts.plugins) load_plugin(path);  // before any method is named
    set_plugin_isolation(opts.isolate);
    std::vector<char*> args(argv, argv + argc);
    for (auto& e : extra) args.push_back(e.data());
    int n = static_cast<int>(args.size());
    args.push_back(nullptr);
    benchmark::Initialize(&n, args.data(), [] {  // --help: our flags, then Google Benchmark's
      std::fputs(bench::own_flags_help(), stdout);
      benchmark::PrintDefaultHelp();
    });
    if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;

    // A study run keeps the terminal for progress and the verdict: Google Benchmark's
    // table goes to bench.json beside the study (or where --benchmark_out says), and to
    // the terminal only when asked for.
    const bool study_run = !opts.study_out.empty() && !opts.list_only;
    const bool show_table = !study_run || opts.verbose || !opts.benchmark_format.empty();
    const std::string bench_json = study_run && opts.benchmark_out.empty()
                                       ? (std::filesystem::path(opts.study_out).parent_path() / "bench.json").string()
                                       : std::string();
    if (study_run) check_writable(opts.study_out);
    if (!bench_json.empty()) check_writable(bench_json);

    // The accuracy sweep first: it gives each case its counters and the study its rows.
    sweep_options sopts;
    if (opts.quick) find_preset("quick").apply(sopts);
    if (!opts.parts.empty()) sopts.parts = opts.parts;
    sopts.overrides = opts.overrides;
    sopts.problems = opts.problems;
    sopts.shard_index = opts.shard_index;
    sopts.shard_count = opts.shard_count;
    // Before any output: one line and exit 2 on a bad name or value.
    validate(sopts);
    // A listing names the cases, which only the parts with timed cases make
    // (case_book::register_all): the other parts are not run for it (the quick listing
    // took 31 s with every part, 12 s with the sweep and substeps parts, on the 2-core
    // machine).
    const auto parts = selected_parts(sopts);  // throws for an unknown part name
    if (opts.list_only) {
      std::vector<std::string> named;
      for (const auto* p : parts)
        if (p->has_timed_cases) named.emplace_back(p->name);
      if (!named.empty()) sopts.parts = named;
    }
    // A shard's JSON names its shard, as `stepbench merge --bench` checks against its study.
    if (sopts.shard_count > 1)
      benchmark::AddCustomContext(bench_shard_key, fmt::format("{}/{}", sopts.shard_index + 1, sopts.shard_count));
    bench::progress_line progress("stepbench_bench", !opts.list_only);
    const auto start = std::chrono::steady_clock::now();
    // A shard sweeps and times only its share of the problems (study/sweep.hpp sweep_shard).
    const auto share = shard_problems(sopts);
    progress.begin(
        fmt::format(
            "sweeping {} for accuracy{}", count_of(share.size(), "problem"),
            sopts.shard_count > 1 ? fmt::format(" (shard {} of {})", sopts.shard_index + 1, sopts.shard_count) : ""),
        sweep_parts(sopts), "parts");
    sopts.on_progress = [&](std::size_t, std::size_t) { progress.advance(); };
    sopts.on_warning = [&](const std::string& line) {
      progress.around([&] { std::fprintf(stderr, "%s\n", line.c_str()); });
    };
    study s = run_sweep(sopts);
    progress.end(fmt::format("swept {} ({}) in {}", count_of(s.problems.size(), "problem"),
                             count_of(run_count(s), "run"), bench::format_duration(s.wall_seconds)));

    bench::case_book book(opts.case_budget_s);
    book.register_all(s);
    // The scaling families of the shard's problems only (an empty list selects every one).
    if (sopts.shard_count == 1 || !share.empty())
      bench::register_scaling(sopts.shard_count == 1 ? opts.problems : share);
    const std::size_t total = opts.list_only ? 0 : count_selected(argv[0]);

    // The display reporter is made after Initialize, from the flags it parsed.
    benchmark::JSONReporter json;
    std::ostringstream json_text;
    json.SetOutputStream(&json_text);
    json.SetErrorStream(&json_text);
    bench::collecting_reporter reporter(show_table ? benchmark::CreateDefaultDisplayReporter() : nullptr,
                                        bench_json.empty() ? nullptr : &json, book, progress, opts.verbose);
    const char* mode = opts.quick ? "quick" : "full";
    const auto timing_start = std::chrono::steady_clock::now();
    if (total > 0) progress.begin("timing", total, "cases");
    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::Shutdown();
    if (total > 0)
      progress.end(
          fmt::format("timed {} ({} mode) in {}", count_of(total, "case"), mode,
                      bench::format_duration(
                          std::chrono::duration<double>(std::chrono::steady_clock::now() - timing_start).count())));
    if (opts.list_only) return 0;

    if (!opts.study_out.empty() && book.timed_count() == 0 && !share.empty())
      throw std::runtime_error("no case was timed (does --benchmark_filter match any?); " + opts.study_out +
                               " was not written");
    book.merge_into_rows();
    timing_settings& ts = s.timed.emplace(reporter.machine);
    ts.mode = mode;
    ts.min_time_s = opts.min_time_s;
    ts.repetitions = opts.repetitions;
    ts.case_budget_s = opts.case_budget_s;
    ts.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    judge_study(s);  // the verdict again, on the measured times
    if (opts.study_out.empty()) return report_study_outcome(s, "stepbench_bench", opts.strict);
    // The study first, then bench.json: a signal between the two leaves the new study
    // whole and the previous bench.json (the study is what the other commands read).
    write_study(s, opts.study_out);
    if (!bench_json.empty()) {
      const std::string text = json_text.str();
      write_image({text.begin(), text.end()}, bench_json);  // whole or not at all, as the study file
    }
    std::fflush(stdout);
    fmt::print(stderr,
               "stepbench_bench: wrote {}{} ({} mode, {} timed) in {}; `stepbench ratios --study {}` prints the "
               "performance ratios\n",
               opts.study_out, bench_json.empty() ? "" : " and " + bench_json, ts.mode,
               count_of(book.timed_count(), "case"), bench::format_duration(ts.wall_seconds), opts.study_out);
    const int status = report_study_outcome(s, "stepbench_bench", opts.strict);
    // The answer last: the verdict tables (on stderr when stdout carries Google
    // Benchmark's JSON or CSV).
    std::FILE* verdict_to =
        show_table && !opts.benchmark_format.empty() && opts.benchmark_format != "console" ? stderr : stdout;
    fmt::print(verdict_to, "\n{}", format_verdict_text(s));
    return status;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "stepbench_bench: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stepbench_bench: error: %s\n", e.what());
    return 1;
  }
}

#include "bench/timings.hpp"

#include <sstream>

namespace stepbench::bench {
namespace {

// The lines of a context header to show: every line but Google Benchmark's DEBUG-build
// warning (all of them when `verbose`); only the "***WARNING***" lines when `warnings_only`.
std::string shown_context(const std::string& header, bool warnings_only, bool verbose) {
  std::istringstream in(header);
  std::string out, line;
  while (std::getline(in, line)) {
    const bool warning = line.rfind("***WARNING***", 0) == 0;
    if (warnings_only && !warning) continue;
    if (!verbose && line.rfind("***WARNING*** Library was built as DEBUG", 0) == 0) continue;
    out += line + "\n";
  }
  return out;
}

}  // namespace

bool collecting_reporter::ReportContext(const Context& context) {
  machine.cpu_scaling_enabled = context.cpu_info.scaling == benchmark::CPUInfo::ENABLED    ? 1
                                : context.cpu_info.scaling == benchmark::CPUInfo::DISABLED ? 0
                                                                                           : -1;
  machine.num_cpus = context.cpu_info.num_cpus;
  machine.mhz_per_cpu = context.cpu_info.cycles_per_second / 1e6;
  bool ok = !file_ || file_->ReportContext(context);
  progress_.around([&] {
    // The console and CSV reporters print the header to their error stream (the JSON one
    // puts it in the document): caught here, and passed on filtered.
    std::ostringstream header;
    if (display_) {
      display_->SetOutputStream(&GetOutputStream());
      display_->SetErrorStream(&header);
      ok = display_->ReportContext(context) && ok;
      display_->SetErrorStream(&GetErrorStream());
    } else {
      PrintBasicContext(&header, context);
    }
    GetErrorStream() << shown_context(header.str(), display_ == nullptr, verbose_) << std::flush;
  });
  return ok;
}

void collecting_reporter::ReportRuns(const std::vector<Run>& runs) {
  for (const auto& r : runs) {
    if (r.run_type != Run::RT_Iteration) continue;
    timed_case* c = book_.find(r.run_name.function_name);
    if (!c) continue;
    if (r.error_occurred)
      c->skipped = r.error_message;
    else if (r.iterations > 0)
      c->ns_per_run.push_back(r.real_accumulated_time * 1e9 / static_cast<double>(r.iterations));
  }
  if (file_) file_->ReportRuns(runs);
  if (display_) progress_.around([&] { display_->ReportRuns(runs); });
  // Google Benchmark reports a case once all its repetitions ran (then its aggregates, in a
  // second call): a case is done when its iteration runs come.
  if (!runs.empty() && runs.front().run_type == Run::RT_Iteration) progress_.advance();
}

void collecting_reporter::Finalize() {
  if (file_) file_->Finalize();
  if (display_) progress_.around([&] { display_->Finalize(); });
}

}  // namespace stepbench::bench

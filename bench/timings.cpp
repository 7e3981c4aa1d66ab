#include "bench/timings.hpp"

#include <fmt/format.h>

namespace stepbench::bench {

bool collecting_reporter::ReportContext(const Context& context) {
  cpu_scaling = context.cpu_info.scaling == benchmark::CPUInfo::ENABLED    ? 1
                : context.cpu_info.scaling == benchmark::CPUInfo::DISABLED ? 0
                                                                           : -1;
  num_cpus = context.cpu_info.num_cpus;
  mhz = context.cpu_info.cycles_per_second / 1e6;
  // The display reporter writes to the streams Google Benchmark gave this reporter.
  display_->SetOutputStream(&GetOutputStream());
  display_->SetErrorStream(&GetErrorStream());
  return display_->ReportContext(context);
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
  display_->ReportRuns(runs);
  if (!runs.empty() && runs.front().run_type == Run::RT_Iteration && book_.find(runs.front().run_name.function_name))
    ++reported_;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_progress_ > std::chrono::seconds(10)) {
    last_progress_ = now;
    fmt::print(stderr, "stepbench_bench: {} of {} cases timed ({:.0f} s)\n", reported_, book_.size(),
               std::chrono::duration<double>(now - start_).count());
  }
}

}  // namespace stepbench::bench

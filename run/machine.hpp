#pragma once
// Where and when a study was made, as its root attributes say it: the CPU model, the
// number of cores and the time of writing.
#include <cstddef>
#include <functional>
#include <string>

namespace stepbench {

// "Intel(R) Xeon(R) ..." from /proc/cpuinfo, or "unknown".
std::string cpu_model();
// The hardware threads the standard library reports (0 when unknown).
int core_count();
// "2026-12-01T09:30:00Z".
std::string utc_now_iso8601();

// Runs body(i) for every i in [0, n), each once, on `jobs` threads (0: one a core; this
// thread is one of them), then after_each() under one lock. Each body writes only its
// own slot, so the result does not depend on the threads. After an exception the
// threads stop at their current index and the lowest-indexed exception is rethrown here.
// after_each reports progress: an exception from it is dropped, and the work goes on.
void parallel_indices(std::size_t n, int jobs, const std::function<void(std::size_t)>& body,
                      const std::function<void()>& after_each);

}  // namespace stepbench

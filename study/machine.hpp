#pragma once
// Where and when a study was made, as its root attributes say it: the CPU model, the
// number of cores and the time of writing.
#include <string>

namespace stepbench {

// "Intel(R) Xeon(R) ..." from /proc/cpuinfo, or "unknown".
std::string cpu_model();
// The hardware threads the standard library reports (0 when unknown).
int core_count();
// "2026-12-01T09:30:00Z".
std::string utc_now_iso8601();

}  // namespace stepbench

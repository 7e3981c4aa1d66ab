#include "run/machine.hpp"

#include <algorithm>
#include <atomic>
#include <ctime>
#include <exception>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

namespace stepbench {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

int core_count() { return static_cast<int>(std::thread::hardware_concurrency()); }

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void parallel_indices(std::size_t n, int jobs, const std::function<void(std::size_t)>& body,
                      const std::function<void()>& after_each) {
  std::vector<std::exception_ptr> failures(n);
  std::atomic<std::size_t> next{0};
  std::mutex lock;
  const auto worker = [&] {
    for (std::size_t i; (i = next++) < n;) {
      try {
        body(i);
      } catch (...) {
        failures[i] = std::current_exception();
        next = n;  // the others stop at their current index
      }
      std::lock_guard guard(lock);
      // Progress must never end a run: a report that fails (stderr closed) is dropped,
      // where it would otherwise leave the thread and terminate the process.
      try {
        if (after_each) after_each();
      } catch (...) {
      }
    }
  };
  const int threads =
      static_cast<int>(std::min<std::size_t>(std::max(1, jobs > 0 ? jobs : core_count()), std::max<std::size_t>(n, 1)));
  {
    std::vector<std::jthread> others;
    for (int t = 1; t < threads; ++t) others.emplace_back(worker);
    worker();
  }
  for (const auto& failure : failures)
    if (failure) std::rethrow_exception(failure);
}

}  // namespace stepbench

#pragma once
// While a study file is written to its temporary path, SIGINT, SIGTERM and SIGHUP remove
// that temporary file before ending the process as they would have: an interrupted run
// leaves the previous results file byte-identical and nothing else behind. (Before the
// write there is nothing to clean up: the previous file is only ever replaced by a
// rename.) SIGXFSZ is ignored meanwhile, so that a file-size limit (ulimit -f) fails the
// write with EFBIG, reported, instead of killing the process. One guard at a time; the
// previous handlers come back when it ends.
#include <csignal>
#include <string>

namespace stepbench {

class temp_file_guard {
 public:
  explicit temp_file_guard(const std::string& temp_path);
  ~temp_file_guard();
  temp_file_guard(const temp_file_guard&) = delete;
  temp_file_guard& operator=(const temp_file_guard&) = delete;

 private:
  static constexpr int signals_[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction previous_[3];
  struct sigaction previous_file_size_;
};

}  // namespace stepbench

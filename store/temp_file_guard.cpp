#include "store/temp_file_guard.hpp"

#include <unistd.h>

#include <cstdio>
#include <iterator>

namespace stepbench {
namespace {

// The temporary file being written, for the signal handler below (a fixed buffer: a
// handler may only call async-signal-safe functions, such as unlink and raise).
char temp_being_written[4096] = {0};

extern "C" void remove_temp_and_reraise(int sig) {
  if (temp_being_written[0]) ::unlink(temp_being_written);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

temp_file_guard::temp_file_guard(const std::string& temp_path) {
  std::snprintf(temp_being_written, sizeof temp_being_written, "%s", temp_path.c_str());
  struct sigaction action {};
  action.sa_handler = remove_temp_and_reraise;
  sigemptyset(&action.sa_mask);
  for (std::size_t i = 0; i < std::size(signals_); ++i) sigaction(signals_[i], &action, &previous_[i]);
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &ignore, &previous_file_size_);
}

temp_file_guard::~temp_file_guard() {
  for (std::size_t i = 0; i < std::size(signals_); ++i) sigaction(signals_[i], &previous_[i], nullptr);
  sigaction(SIGXFSZ, &previous_file_size_, nullptr);
  temp_being_written[0] = 0;
}

}  // namespace stepbench

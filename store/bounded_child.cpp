#include "store/bounded_child.hpp"

#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "store/study_file.hpp"

namespace stepbench {
std::string read_to_end(int fd) {
  std::string out;
  char buf[1 << 12];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return out;
    out.append(buf, static_cast<std::size_t>(n));
  }
}

void bound_child(long cpu_seconds, std::size_t memory_bytes) {
  const rlimit cpu{static_cast<rlim_t>(cpu_seconds), static_cast<rlim_t>(cpu_seconds)};
  ::setrlimit(RLIMIT_CPU, &cpu);
#if !defined(__SANITIZE_ADDRESS__)
  const rlimit memory{memory_bytes, memory_bytes};
  ::setrlimit(RLIMIT_AS, &memory);
#else
  (void)memory_bytes;
#endif
}

std::string abnormal_end(int status, long cpu_seconds, std::string_view doing) {
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU)
    return fmt::format("damaged: {} did not end within {} s of CPU time (HDF5 looping on it)", doing, cpu_seconds);
  // Stopped from outside (an interrupt, or the kernel's out-of-memory killer): not the file's doing.
  if (WIFSIGNALED(status))
    for (const int outside : {SIGINT, SIGTERM, SIGHUP, SIGKILL})
      if (WTERMSIG(status) == outside) return fmt::format("{} was stopped (SIG{})", doing, sigabbrev_np(outside));
  if (WIFSIGNALED(status))
    return fmt::format("damaged: {} crashes the HDF5 library (SIG{})", doing, sigabbrev_np(WTERMSIG(status)));
  return fmt::format("damaged: {} crashes the HDF5 library (exit {})", doing, WEXITSTATUS(status));
}

int run_in_bounded_child(const std::function<int()>& work, long cpu_seconds, std::size_t memory_bytes,
                         std::string_view doing, const std::function<void(const std::string&)>& on_abnormal_end) {
  // The child's stderr goes to a file of its own until it has ended: a crash's own
  // report (a sanitizer's, many lines) is not the command's one line.
  std::FILE* err = std::tmpfile();
  int fds[2];
  if (!err || ::pipe(fds) != 0) {
    if (err) std::fclose(err);
    throw std::runtime_error(fmt::format("cannot start the process for {}: {}", doing, std::strerror(errno)));
  }
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]), ::close(fds[1]), std::fclose(err);
    throw std::runtime_error(fmt::format("cannot start the process for {}: {}", doing, std::strerror(errno)));
  }
  if (child == 0) {
    ::close(fds[0]);
    bound_child(cpu_seconds, memory_bytes);
    ::dup2(::fileno(err), STDERR_FILENO);
    // The answer: 'O' and the exit code, or the exception: 'I' (invalid_argument), 'E'.
    std::string answer;
    try {
      answer = fmt::format("O{}", work());
    } catch (const std::invalid_argument& e) {
      answer = std::string("I") + e.what();
    } catch (const std::exception& e) {
      answer = std::string("E") + e.what();
    }
    std::fflush(nullptr);
    write_bytes(fds[1], answer.data(), answer.size());  // failing when the parent is gone: nothing to tell
    std::_Exit(0);
  }
  ::close(fds[1]);
  const std::string answer = read_to_end(fds[0]);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0)
    if (errno != EINTR) {
      std::fclose(err);
      throw std::runtime_error(fmt::format("cannot wait for the process of {}: {}", doing, std::strerror(errno)));
    }
  const bool ended_by_itself = WIFEXITED(status) && WEXITSTATUS(status) == 0 && !answer.empty();
  if (ended_by_itself) {
    ::lseek(::fileno(err), 0, SEEK_SET);  // the child's writes moved the offset it shares
    std::fputs(read_to_end(::fileno(err)).c_str(), stderr);
  }
  std::fclose(err);
  if (!ended_by_itself) {
    on_abnormal_end(abnormal_end(status, cpu_seconds, doing));
    throw std::logic_error("run_in_bounded_child: on_abnormal_end returned");
  }
  if (answer[0] == 'O') return std::stoi(answer.substr(1));
  if (answer[0] == 'I') throw std::invalid_argument(answer.substr(1));
  throw std::runtime_error(answer.substr(1));
}

}  // namespace stepbench

#pragma once
// One live progress line on stderr for the long phases of a run (the accuracy sweep, the
// timing of the cases): what is being done, how many of how many, the time elapsed and
// the time left at the rate so far. On a terminal (isatty) it is a bar redrawn in place
// with \r, once a second and as cases finish; elsewhere (a CI log, a pipe) a plain line
// every 10 s. A phase ends with one summary line in place of the live one.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace stepbench::bench {

// "42 s", "3 min 05 s", "1 h 02 min".
std::string format_duration(double seconds);

class progress_line {
 public:
  // `enabled` false: nothing is ever printed (a listing run).
  progress_line(std::string program, bool enabled);
  ~progress_line();
  progress_line(const progress_line&) = delete;
  progress_line& operator=(const progress_line&) = delete;

  // Starts a phase: "timing" with a total of 3348 and the unit "cases" reads "timing 12 of
  // 3348 cases"; a total of 0 (not known) shows the time elapsed only.
  void begin(std::string what, std::size_t total = 0, std::string unit = {});
  void advance();  // one more of the total done
  // Ends the phase: the live line gives way to "<program>: <summary>".
  void end(const std::string& summary);
  // Runs `print` (output to the same terminal) with the live line cleared, then redraws it.
  void around(const std::function<void()>& print);

 private:
  std::string line_locked(bool bar) const;
  void draw_locked();
  void clear_locked();
  void tick();

  std::string program_;
  bool enabled_, tty_;
  std::mutex m_;
  std::condition_variable wake_;
  std::thread ticker_;
  bool active_ = false, stop_ = false, drawn_ = false;
  std::string what_, unit_;
  std::size_t total_ = 0, done_ = 0;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace stepbench::bench

#include "bench/progress.hpp"

#include <fmt/format.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace stepbench::bench {

using clock_type = std::chrono::steady_clock;

std::string format_duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (seconds < 9.95) return fmt::format("{:.1f} s", std::max(0.0, seconds));
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

progress_line::progress_line(std::string program, bool enabled)
    : program_(std::move(program)), enabled_(enabled), tty_(::isatty(STDERR_FILENO) == 1) {}

progress_line::~progress_line() {
  if (active_) end("");  // an exception on its way out: clear the line, say nothing
}

std::string progress_line::line_locked(bool bar) const {
  const double elapsed = std::chrono::duration<double>(clock_type::now() - start_).count();
  std::string out = what_;
  if (total_ > 0) {
    if (bar) {
      constexpr std::size_t width = 20;
      const std::size_t filled = std::min(width, done_ * width / total_);
      out += fmt::format(" [{}{}]", std::string(filled, '#'), std::string(width - filled, '.'));
    }
    out += fmt::format(" {} of {} {}, {} elapsed", done_, total_, unit_, format_duration(elapsed));
    if (done_ > 0 && done_ < total_)
      out += fmt::format(", about {} left",
                         format_duration(elapsed * static_cast<double>(total_ - done_) / static_cast<double>(done_)));
  } else {
    out += fmt::format(", {} elapsed", format_duration(elapsed));
  }
  return out;
}

void progress_line::draw_locked() {
  if (!enabled_ || !active_) return;
  last_draw_ = clock_type::now();
  if (!tty_) {
    fmt::print(stderr, "{}: {}\n", program_, line_locked(false));
    std::fflush(stderr);
    return;
  }
  std::string text = line_locked(true);
  winsize w{};  // the terminal's width in columns (80 when it does not say)
  const std::size_t columns = ::ioctl(STDERR_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0 ? w.ws_col : 80;
  if (text.size() >= columns) text.resize(columns - 1);  // a wrapped line cannot be redrawn with \r
  fmt::print(stderr, "\r\033[K{}", text);
  std::fflush(stderr);
  drawn_ = true;
}

void progress_line::clear_locked() {
  if (drawn_) {
    fmt::print(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
  }
}

void progress_line::tick() {
  const auto period = tty_ ? std::chrono::seconds(1) : std::chrono::seconds(10);
  std::unique_lock lock(m_);
  while (!stop_) {
    const auto due = last_draw_ + period;  // a redraw by advance() moves it on
    if (clock_type::now() >= due)
      draw_locked();
    else
      wake_.wait_until(lock, due);
  }
}

void progress_line::begin(std::string what, std::size_t total, std::string unit) {
  if (active_) end("");
  {
    std::lock_guard lock(m_);
    what_ = std::move(what);
    unit_ = std::move(unit);
    total_ = total;
    done_ = 0;
    start_ = last_draw_ = clock_type::now();
    active_ = true;
    stop_ = false;
    if (tty_) draw_locked();  // a plain log gets its first line after 10 s: short runs stay quiet
  }
  if (enabled_) ticker_ = std::thread([this] { tick(); });
}

void progress_line::advance() {
  std::lock_guard lock(m_);
  ++done_;
  // On a terminal, the count follows the cases (at most 10 redraws a second).
  if (tty_ && clock_type::now() - last_draw_ > std::chrono::milliseconds(100)) draw_locked();
}

void progress_line::end(const std::string& summary) {
  {
    std::lock_guard lock(m_);
    stop_ = true;
  }
  wake_.notify_all();
  if (ticker_.joinable()) ticker_.join();
  std::lock_guard lock(m_);
  clear_locked();
  active_ = false;
  if (enabled_ && !summary.empty()) fmt::print(stderr, "{}: {}\n", program_, summary);
}

void progress_line::around(const std::function<void()>& print) {
  std::lock_guard lock(m_);
  const bool redraw = drawn_;
  clear_locked();
  print();
  std::cout.flush();
  std::fflush(stdout);
  if (redraw) draw_locked();
}

}  // namespace stepbench::bench

#include "core/drive.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace stepbench {

std::vector<record_point> plan_records(double horizon, double dt, std::span<const double> times) {
  const long n = steps_for(horizon, dt);
  std::vector<record_point> plan;
  plan.reserve(times.size());
  for (std::size_t j = 0; j < times.size(); ++j) {
    const double t = times[j];
    if (!(t > 0.0 && t <= horizon) || (j > 0 && !(t > times[j - 1])))
      throw std::invalid_argument(
          fmt::format("record times must increase within (0, {:g}]; time {} is {:g}", horizon, j, t));
    const long i = std::lround(t / dt);
    record_point p{t, i, true};
    if (t == horizon || (i >= n && std::abs(t - horizon) <= 1e-9 * dt)) {
      p.step = n;
      p.t = horizon;
    } else if (i >= 1 && i < n && std::abs(t - static_cast<double>(i) * dt) <= 1e-9 * dt) {
      p.t = static_cast<double>(i) * dt;  // the grid's own time, as the loop computes it
    } else {
      p.step = std::clamp(static_cast<long>(std::floor(t / dt)) + 1, 1L, n);
      p.on_grid = false;
    }
    if (!plan.empty() && p.step == plan.back().step && p.on_grid && plan.back().on_grid)
      throw std::invalid_argument(
          fmt::format("record times {:g} and {:g} fall on the same step of dt {:g}", plan.back().t, t, dt));
    plan.push_back(p);
  }
  return plan;
}

std::vector<double> nearest_grid_times(double horizon, double dt, int count) {
  const long n = steps_for(horizon, dt);
  std::vector<double> out;
  long last = 0;
  for (int j = 1; j <= count; ++j) {
    const double t = horizon * j / count;
    const long i = j == count ? n : std::clamp(std::lround(t / dt), 1L, n);
    if (i > last) {
      out.push_back(time_after_step(i, n, dt, horizon));
      last = i;
    }
  }
  return out;
}

std::vector<double> sample_times(double horizon, int count) {
  std::vector<double> out;
  for (int j = 1; j <= count; ++j) out.push_back(j == count ? horizon : horizon * j / count);
  return out;
}

}  // namespace stepbench

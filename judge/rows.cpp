#include "judge/rows.hpp"

#include <stdexcept>

namespace stepbench {

double metric_value(const run_metrics& m, const std::string& metric) {
  if (metric == "err_pos_max") return m.err_pos_max;
  if (metric == "err_pos_final") return m.err_pos_final;
  if (metric == "err_pos_rms") return m.err_pos_rms;
  if (metric == "err_vel_final") return m.err_vel_final;
  throw std::logic_error("unknown metric " + metric);
}

std::vector<wp_method> work_precision_input(const problem_study& ps, const std::string& metric) {
  std::vector<wp_method> out;
  for (const auto& ms : ps.methods) {
    wp_method m{ms.info.name, ms.info.origin, ms.info.kind, {}};
    for (const auto& r : ms.rows)
      m.rows.push_back({r.param, metric_value(r.metrics, metric), r.time.time_ns,
                        static_cast<double>(r.work.force_evals), r.metrics.completed(), r.metrics.diverged, r.time.cut,
                        r.time.time_ns_min, r.time.time_ns_max});
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace stepbench

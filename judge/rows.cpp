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

std::vector<wp_method> work_precision_input(const study_problem& p, const std::string& metric, bool timed) {
  std::vector<wp_method> out;
  for (const auto& m : p.methods) {
    wp_method w{m.name, m.origin, m.kind, {}};
    const auto& param = m.col("param");
    const auto& err = m.col(metric);
    const auto& evals = m.col("force_evals");
    const auto& diverged = m.col("diverged");
    const auto& failed = m.col("failed");
    const auto& skipped = m.col("skipped");
    const std::vector<double> none(param.size(), std::numeric_limits<double>::quiet_NaN()), zeros(param.size(), 0.0);
    const auto& time = timed ? m.col("time_ns") : none;
    const auto& cut = timed ? m.col("cut") : zeros;
    const auto& time_lo = timed ? m.col("time_ns_min") : none;
    const auto& time_hi = timed ? m.col("time_ns_max") : none;
    for (std::size_t i = 0; i < param.size(); ++i)
      w.rows.push_back({param[i], err[i], time[i], evals[i],
                        row_completed(diverged[i] != 0, failed[i] != 0, skipped[i] != 0), diverged[i] != 0, cut[i] != 0,
                        time_lo[i], time_hi[i]});
    out.push_back(std::move(w));
  }
  return out;
}

}  // namespace stepbench

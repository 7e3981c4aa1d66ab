#include "study/advise.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "study/table_render.hpp"

namespace stepbench {
namespace {

std::string cost_text(const std::string& cost, const wp_row& r) {
  return cost == "force_evals" ? fmt::format("{:.0f} force evals", r.force_evals) : format_time_ns(r.time_ns);
}

std::string label(const wp_method& m) {
  switch (m.origin) {
    case method_origin::peer:
      return m.name + " (peer)";
    case method_origin::baseline:
      return m.name + " (baseline, for scale)";
    default:
      return m.name;
  }
}

}  // namespace

advice advise(const study_data& study, const std::string& problem, const std::string& metric, double tol) {
  if (!is_error_metric(metric))
    throw std::invalid_argument(fmt::format("unknown metric '{}' (known: {})", metric, fmt::join(error_metrics, ", ")));
  if (!(tol > 0.0) || !std::isfinite(tol)) throw std::invalid_argument(fmt::format("--tol must be > 0, got {}", tol));
  const study_problem* p = study.find(problem);
  if (!p) {
    std::vector<std::string> names;
    for (const auto& q : study.problems) names.push_back(q.name);
    throw std::invalid_argument(fmt::format("problem '{}' is not in the study file '{}' (it has: {})", problem,
                                            study.path,
                                            names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
  }
  advice a;
  a.problem = problem;
  a.metric = metric;
  a.unit = metric == "err_vel_final" ? p->unit + "/s" : p->unit;
  a.tol = tol;
  a.timed = study.timed;
  a.methods = work_precision_input(*p, metric, study.timed);
  a.result = cheapest(a.methods, tol, study.timed, metric, a.unit);
  return a;
}

std::string format_advice(const advice& a, std::size_t runners_up) {
  const auto& r = a.result;
  std::string out;
  const std::string cost_name = r.cost == "time_ns" ? "measured time per run (median)"
                                : a.timed           ? "force evaluations (some qualifying rows are not timed)"
                                                    : "force evaluations (the study has no timings)";
  // The stability margin: how far the chosen row is from the rows that blew up.
  auto margin = [&](const wp_pick& p) {
    const auto kind = a.methods[p.method].kind;
    if (!p.largest_diverged) return std::string("never diverged in the study");
    if (p.diverged_rows == 1) return fmt::format("diverged at {}", format_param(kind, *p.largest_diverged));
    return fmt::format("diverged at {} rows: {} .. {}", p.diverged_rows, format_param(kind, *p.smallest_diverged),
                       format_param(kind, *p.largest_diverged));
  };
  out += fmt::format("{}: {} <= {:g} {}; cost = {}\n", a.problem, a.metric, a.tol, a.unit, cost_name);
  const auto answer = r.answer(a.methods);
  if (!answer) {
    out += fmt::format("no method in the study meets {} <= {:g} {} on {}", a.metric, a.tol, a.unit, a.problem);
    if (r.best_achieved) {
      const auto& m = a.methods[r.best_achieved->method];
      out +=
          fmt::format("; the best achieved is {} {:.3g} {} by {} at {}", a.metric, m.rows[r.best_achieved->row].error,
                      a.unit, m.name, format_param(m.kind, m.rows[r.best_achieved->row].param));
    }
    out += "\n";
  } else {
    const auto& m = a.methods[answer->method];
    const auto& row = m.rows[answer->row];
    out += fmt::format("use {} at {}: {}, {} {:.3g} {}; {}\n", label(m), format_param(m.kind, row.param),
                       cost_text(r.cost, row), a.metric, row.error, a.unit, margin(*answer));
  }
  std::vector<const wp_pick*> others;
  for (const auto& p : r.ranked)
    if (!answer || p.method != answer->method) others.push_back(&p);
  if (!others.empty()) {
    table t{{right_column("rank"),
             {"method"},
             {"dt or tolerance"},
             right_column("cost"),
             right_column(a.metric, a.unit),
             {"stability margin"}},
            {}};
    for (std::size_t i = 0; i < others.size() && i < runners_up; ++i) {
      const auto& m = a.methods[others[i]->method];
      const auto& row = m.rows[others[i]->row];
      t.add({fmt::format("{}.", i + 2), label(m), format_param(m.kind, row.param), cost_text(r.cost, row),
             fmt::format("{:.3g}", row.error), margin(*others[i])});
    }
    out += (answer ? "runners-up:\n" : "for scale:\n") + render_text(t);
    if (others.size() > runners_up)
      out += fmt::format("  ... and {} more that also meet the tolerance\n", others.size() - runners_up);
  }
  if (!r.excluded.empty()) {
    table t{{{"method"}, {"reason"}}, {}};
    for (const auto& e : r.excluded) t.add({label(a.methods[e.method]), e.reason});
    out += "excluded:\n" + render_text(t);
  }
  return out;
}

}  // namespace stepbench

#include "judge/substeps.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/number.hpp"
#include "core/work_precision.hpp"

namespace stepbench {
namespace {

double cost_of(const method_row& r, bool by_time) {
  return by_time ? r.time.time_ns : static_cast<double>(r.work.force_evals);
}

// "removes 0.72 of the energy scale beyond the damper" or "keeps 0.27 more than the damper leaves".
std::string damping_text(double d) {
  if (!std::isfinite(d)) return "no energy figure";
  return d >= 0 ? fmt::format("removes {:.2g} of the energy scale beyond the damper", d)
                : fmt::format("keeps {:.2g} of the energy scale more than the damper leaves", -d);
}

std::string describe(const substep_verdict& v) {
  const bool by_time = v.cost_kind == "time_ns";
  auto cost = [&](double c) { return by_time ? format_time_ns(c) : fmt::format("{:.0f} force evaluations", c); };
  std::string s = fmt::format(
      "{}: one {} step a frame costs {} over the run for a max position error of {:.3g} and {}; ", v.problem,
      v.implicit_method, cost(v.implicit_cost), v.implicit_error, damping_text(v.implicit_damping));
  if (v.substeps_at_equal_cost == 0) {
    // By time, a run that diverged has no time (it is not timed), so "none costs as
    // little" may mean that the cheap counts diverged.
    s += by_time ? fmt::format("no timed {} run costs as little (the substep counts that diverge are not timed)",
                               v.explicit_method)
                 : fmt::format("even one {} step costs more", v.explicit_method);
  } else if (!std::isfinite(v.explicit_error)) {
    s += fmt::format("at that cost {} affords {} substep{}, which diverge{}", v.explicit_method,
                     v.substeps_at_equal_cost, v.substeps_at_equal_cost == 1 ? "" : "s",
                     v.substeps_at_equal_cost == 1 ? "s" : "");
  } else {
    s += fmt::format("at that cost {} affords {} substeps: error {:.3g} ({}) and {}", v.explicit_method,
                     v.substeps_at_equal_cost, v.explicit_error,
                     v.explicit_error < v.implicit_error
                         ? fmt::format("{:.3g}x smaller", v.implicit_error / v.explicit_error)
                         : fmt::format("{:.3g}x larger", v.explicit_error / v.implicit_error),
                     damping_text(v.explicit_damping));
  }
  if (v.substeps_to_match > 0)
    s += fmt::format("; {} substeps match its error at {}", v.substeps_to_match, cost(v.cost_to_match));
  else
    s += fmt::format("; no number of substeps up to the largest tried matches its error");
  return s;
}

}  // namespace

std::vector<substep_verdict> substep_verdicts(const substep_study& s, bool timed) {
  // Time is the cost when every completed row has one; else force evaluations.
  bool by_time = timed;
  for (const auto& m : s.methods)
    for (const auto& r : m.rows)
      if (r.row.metrics.completed() && !(std::isfinite(r.row.time.time_ns) && r.row.time.time_ns > 0)) by_time = false;
  std::vector<substep_verdict> out;
  for (const auto& im : s.methods) {
    if (im.rows.size() != 1 || !im.info.traits.needs_jacobian) continue;
    const auto& ir = im.rows.front();
    for (const auto& em : s.methods) {
      if (em.info.traits.needs_jacobian) continue;
      substep_verdict v;
      v.problem = s.problem;
      v.implicit_method = im.info.name;
      v.explicit_method = em.info.name;
      v.cost_kind = by_time ? "time_ns" : "force_evals";
      v.implicit_cost = ir.row.metrics.completed() ? cost_of(ir.row, by_time) : nan;
      v.implicit_error = ir.row.metrics.err_pos_max;
      v.implicit_damping = ir.extra_damping;
      v.explicit_cost = v.explicit_error = v.explicit_damping = v.cost_to_match = nan;
      for (const auto& er : em.rows) {
        // Cost as run: a diverged run is still the cost of its steps (its errors are not).
        const double c = cost_of(er.row, by_time);
        if (std::isfinite(c) && c <= v.implicit_cost && er.substeps > v.substeps_at_equal_cost) {
          v.substeps_at_equal_cost = er.substeps;
          v.explicit_cost = c;
          v.explicit_error = er.row.metrics.completed() ? er.row.metrics.err_pos_max : nan;
          v.explicit_damping = er.extra_damping;
        }
        if (er.row.metrics.completed() && er.row.metrics.err_pos_max <= v.implicit_error && v.substeps_to_match == 0) {
          v.substeps_to_match = er.substeps;
          v.cost_to_match = cost_of(er.row, by_time);
        }
      }
      v.summary = describe(v);
      out.push_back(std::move(v));
    }
  }
  return out;
}

}  // namespace stepbench

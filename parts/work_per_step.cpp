// The force evaluations a step each fixed-step method took on each problem, against what
// it declares (/work_per_step; method_info::evals_per_step). Every cost the study ranks
// by rests on counted work (force evaluations where untimed, the scans' cost per
// evaluation), so a declaration the counts contradict is a finding, not a detail.
//
// It is also the example of the shape docs/architecture.md walks through ("Adding an
// analysis"): the result, its table, its run and write, in this one file, and its line
// in parts/registry.cpp. It measures nothing new: it reads the sweep's rows.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "parts/part.hpp"
#include "store/columns.hpp"
#include "study/study.hpp"

namespace stepbench {
namespace work_per_step_detail {

// One method on one problem, over its runs that took a step.
struct work_row {
  std::string problem, method;
  double declared = 0.0;                          // evals_per_step, as the method declares it
  long runs = 0;                                  // the runs counted
  double measured_min = 0.0, measured_max = 0.0;  // force evaluations / steps over those runs
  long extra_max = 0;  // the most evaluations of one run beyond declared x steps (a first step's)
  // Every run took declared x steps evaluations, plus at most one step's worth at the start
  // (a method that reuses its last force evaluates it once before the first step).
  bool agrees = false;
};
struct work_per_step {
  std::vector<work_row> rows;
};

work_per_step count(const study& s) {
  work_per_step out;
  for (const auto& ps : s.problems)
    for (const auto& ms : ps.methods) {
      const double declared = ms.info.evals_per_step;
      if (ms.info.kind != method_kind::fixed_step || !std::isfinite(declared)) continue;
      work_row w{std::string(ps.problem->name()), ms.info.name, declared, 0, INFINITY, 0.0, 0, true};
      for (const auto& r : ms.rows) {
        if (r.steps <= 0) continue;  // skipped: over the work budget
        const double per_step = static_cast<double>(r.work.force_evals) / static_cast<double>(r.steps);
        const double extra = static_cast<double>(r.work.force_evals) - declared * static_cast<double>(r.steps);
        ++w.runs;
        w.measured_min = std::min(w.measured_min, per_step);
        w.measured_max = std::max(w.measured_max, per_step);
        w.extra_max = std::max(w.extra_max, std::lround(extra));
        w.agrees = w.agrees && extra >= 0.0 && extra <= declared;
      }
      if (w.runs > 0) out.rows.push_back(std::move(w));
    }
  return out;
}

// Its table, /work_per_step/rows: declared by this one mapping of its fields to work_row's
// members, which the writer uses and a reader would (`stepbench schema` lists it).
const column_map<work_row>& columns() {
  using R = work_row;
  static const auto columns = column_map<R>("work_per_step", "/work_per_step/rows")
                                  .member("problem", &R::problem)
                                  .member("method", &R::method)
                                  .member("declared", &R::declared)
                                  .member("runs", &R::runs)
                                  .member("measured_min", &R::measured_min)
                                  .member("measured_max", &R::measured_max)
                                  .member("extra_max", &R::extra_max)
                                  .member("agrees", &R::agrees);
  return columns;
}

void write(H5::Group& root, const work_per_step& w) {
  // Only the rows: an attribute summing them would be a second figure for merge to join.
  H5::Group g = root.createGroup("work_per_step");
  columns().write(g, "rows", w.rows);
}

}  // namespace work_per_step_detail

extern const study_part work_per_step_part{
    .name = "work_per_step",
    .summary = "each fixed-step method's counted force evaluations a step against the number it declares",
    .merge = merge_rule::judged_again,  // a row a problem: the shards' rows joined in the study's order
    .tables = {&work_per_step_detail::columns().spec(), 1},
    .describe = [](const sweep_options&) { return std::string("work per step: the sweep's rows"); },
    .run = [](study& s, const part_context&) { s.results.put(work_per_step_detail::count(s)); },
    .write = write_result<work_per_step_detail::work_per_step, work_per_step_detail::write>,
};

}  // namespace stepbench

#include "run/substeps.hpp"

#include <limits>

#include "core/contains.hpp"
#include "core/number.hpp"

namespace stepbench {
namespace {

substep_row run_one(const problem_study& ps, const std::string& method, int n, double frame_dt,
                    const sweep_options& opts) {
  substep_row out;
  out.substeps = n;
  const double dt = frame_dt / n;
  const run_result run = ps.problem->run(method, dt, ps.horizon, ps.truth.times, opts.limits);
  out.row = {dt, run.steps, run.rejected_steps, run.work, measure(*ps.problem, run, ps.truth), {}};
  out.extra_damping = nan;
  if (ps.problem->has_energy() && out.row.metrics.completed() && ps.truth.trusted) {
    double worst = -std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < run.sample_y.size(); ++j)
      worst = std::max(worst, ps.problem->energy(ps.truth.y[j]) - ps.problem->energy(run.sample_y[j]));
    out.extra_damping = worst / ps.truth.energy_scale;
  }
  return out;
}

}  // namespace

std::vector<substep_study> run_substeps(const study& s, const substep_options& opts) {
  std::vector<substep_study> out;
  for (const auto& ps : s.problems) {
    if (!contains(opts.problems, ps.problem->name())) continue;
    substep_study st;
    st.problem = ps.problem->name();
    st.frame_dt = ps.horizon / opts.frames;
    for (const auto& info : ps.problem->methods()) {
      const bool is_implicit = contains(opts.implicit_methods, info.name);
      const bool is_explicit = contains(opts.explicit_methods, info.name);
      if (!is_implicit && !is_explicit) continue;
      substep_method m{info, {}};
      for (int n : is_implicit ? std::vector<int>{1} : opts.counts)
        m.rows.push_back(run_one(ps, info.name, n, st.frame_dt, s.options));
      st.methods.push_back(std::move(m));
    }
    out.push_back(std::move(st));
  }
  return out;
}

}  // namespace stepbench

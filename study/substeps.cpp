#include "study/substeps.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "core/number.hpp"
#include "core/work_precision.hpp"
#include "study/h5.hpp"
#include "study/study_file.hpp"

namespace stepbench {
namespace {

bool completed(const method_row& r) { return r.metrics.completed(); }

double cost_of(const method_row& r, bool by_time) {
  return by_time ? r.time.time_ns : static_cast<double>(r.work.force_evals);
}

substep_row run_one(const problem_study& ps, const std::string& method, int n, double frame_dt,
                    const sweep_options& opts) {
  substep_row out;
  out.substeps = n;
  const double dt = frame_dt / n;
  const run_result run = ps.problem->run(method, dt, ps.horizon, ps.truth.times, opts.limits);
  out.row = {dt, run.steps, run.rejected_steps, run.work, measure(*ps.problem, run, ps.truth), {}};
  out.extra_damping = nan;
  if (ps.problem->has_energy() && completed(out.row) && ps.truth.trusted) {
    double worst = -std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < run.sample_y.size(); ++j)
      worst = std::max(worst, ps.problem->energy(ps.truth.y[j]) - ps.problem->energy(run.sample_y[j]));
    out.extra_damping = worst / ps.truth.energy_scale;
  }
  return out;
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

std::vector<substep_study> run_substeps(const study& s, const substep_options& opts) {
  std::vector<substep_study> out;
  for (const auto& ps : s.problems) {
    if (std::find(opts.problems.begin(), opts.problems.end(), ps.problem->name()) == opts.problems.end()) continue;
    substep_study st;
    st.problem = ps.problem->name();
    st.frame_dt = ps.horizon / opts.frames;
    for (const auto& info : ps.problem->methods()) {
      const bool is_implicit = std::find(opts.implicit_methods.begin(), opts.implicit_methods.end(), info.name) !=
                               opts.implicit_methods.end();
      const bool is_explicit = std::find(opts.explicit_methods.begin(), opts.explicit_methods.end(), info.name) !=
                               opts.explicit_methods.end();
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

std::vector<substep_verdict> substep_verdicts(const substep_study& s, bool timed) {
  // Time is the cost when every completed row has one; else force evaluations.
  bool by_time = timed;
  for (const auto& m : s.methods)
    for (const auto& r : m.rows)
      if (completed(r.row) && !(std::isfinite(r.row.time.time_ns) && r.row.time.time_ns > 0)) by_time = false;
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
      v.implicit_cost = completed(ir.row) ? cost_of(ir.row, by_time) : nan;
      v.implicit_error = ir.row.metrics.err_pos_max;
      v.implicit_damping = ir.extra_damping;
      v.explicit_cost = v.explicit_error = v.explicit_damping = v.cost_to_match = nan;
      for (const auto& er : em.rows) {
        // Cost as run: a diverged run is still the cost of its steps (its errors are not).
        const double c = by_time ? er.row.time.time_ns : static_cast<double>(er.row.work.force_evals);
        if (std::isfinite(c) && c <= v.implicit_cost && er.substeps > v.substeps_at_equal_cost) {
          v.substeps_at_equal_cost = er.substeps;
          v.explicit_cost = c;
          v.explicit_error = completed(er.row) ? er.row.metrics.err_pos_max : nan;
          v.explicit_damping = er.extra_damping;
        }
        if (completed(er.row) && er.row.metrics.err_pos_max <= v.implicit_error && v.substeps_to_match == 0) {
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

void write_substeps(H5::Group& root, const std::vector<substep_study>& studies, bool timed) {
  if (studies.empty()) return;
  H5::Group top = root.createGroup("substeps");
  for (const auto& s : studies) {
    H5::Group g = top.createGroup(s.problem);
    h5::attr(g, "frame_dt", s.frame_dt);
    H5::Group methods = g.createGroup("methods");
    for (const auto& m : s.methods) {
      H5::Group mg = methods.createGroup(m.info.name);
      h5::attr(mg, "origin", std::string(to_string(m.info.origin)));
      h5::attr(mg, "needs_jacobian", static_cast<int>(m.info.traits.needs_jacobian));
      std::vector<method_row> rows;
      std::vector<std::int64_t> n;
      std::vector<double> damping;
      for (const auto& r : m.rows) rows.push_back(r.row), n.push_back(r.substeps), damping.push_back(r.extra_damping);
      h5::table t = runs_table(rows, timed);
      t.add("substeps", n);
      t.add("extra_damping", damping);
      t.write(mg, "runs", schema::find("substeps_runs"));
    }
    const auto verdicts = substep_verdicts(s, timed);
    h5::table v;
    auto col = [&](auto get) {
      using T = decltype(get(verdicts.front()));
      std::vector<T> out;
      for (const auto& x : verdicts) out.push_back(get(x));
      return out;
    };
    v.add("implicit_method", col([](const substep_verdict& x) { return x.implicit_method; }));
    v.add("explicit_method", col([](const substep_verdict& x) { return x.explicit_method; }));
    v.add("cost_kind", col([](const substep_verdict& x) { return x.cost_kind; }));
    v.add("implicit_cost", col([](const substep_verdict& x) { return x.implicit_cost; }));
    v.add("implicit_error", col([](const substep_verdict& x) { return x.implicit_error; }));
    v.add("implicit_damping", col([](const substep_verdict& x) { return x.implicit_damping; }));
    v.add("substeps_at_equal_cost",
          col([](const substep_verdict& x) { return std::int64_t{x.substeps_at_equal_cost}; }));
    v.add("explicit_cost", col([](const substep_verdict& x) { return x.explicit_cost; }));
    v.add("explicit_error", col([](const substep_verdict& x) { return x.explicit_error; }));
    v.add("explicit_damping", col([](const substep_verdict& x) { return x.explicit_damping; }));
    v.add("substeps_to_match", col([](const substep_verdict& x) { return std::int64_t{x.substeps_to_match}; }));
    v.add("cost_to_match", col([](const substep_verdict& x) { return x.cost_to_match; }));
    v.add("summary", col([](const substep_verdict& x) { return x.summary; }));
    v.write(g, "verdict", schema::find("substeps_verdict"));
  }
}

}  // namespace stepbench

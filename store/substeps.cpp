#include "store/substeps.hpp"

#include "judge/substeps.hpp"
#include "store/h5.hpp"
#include "store/study_file.hpp"

namespace stepbench {

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

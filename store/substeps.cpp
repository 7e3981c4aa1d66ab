#include "store/substeps.hpp"

#include "judge/substeps.hpp"
#include "registry/registry.hpp"
#include "store/h5.hpp"
#include "store/study_file.hpp"

namespace stepbench {

const column_map<substep_row>& substep_runs_columns() {
  using R = substep_row;
  static const auto columns = column_map<R>("substeps_runs", "/substeps/<p>/<m>/runs")
                                  .fields(
                                      runs_columns(), [](auto& r) -> auto& { return r.row; })
                                  .member("substeps", &R::substeps)
                                  .member("extra_damping", &R::extra_damping);
  return columns;
}

const auto substep_verdict_columns = column_map<substep_verdict>("substeps_verdict", "/substeps/<p>/verdict")
                                         .member("implicit_method", &substep_verdict::implicit_method)
                                         .member("explicit_method", &substep_verdict::explicit_method)
                                         .member("cost_kind", &substep_verdict::cost_kind)
                                         .member("implicit_cost", &substep_verdict::implicit_cost)
                                         .member("implicit_error", &substep_verdict::implicit_error)
                                         .member("implicit_damping", &substep_verdict::implicit_damping)
                                         .member("substeps_at_equal_cost", &substep_verdict::substeps_at_equal_cost)
                                         .member("explicit_cost", &substep_verdict::explicit_cost)
                                         .member("explicit_error", &substep_verdict::explicit_error)
                                         .member("explicit_damping", &substep_verdict::explicit_damping)
                                         .member("substeps_to_match", &substep_verdict::substeps_to_match)
                                         .member("cost_to_match", &substep_verdict::cost_to_match)
                                         .member("summary", &substep_verdict::summary);

std::vector<schema::table> substeps_tables() { return {substep_runs_columns().spec(), substep_verdict_columns.spec()}; }

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
      substep_runs_columns().write(mg, "runs", m.rows, timed);
    }
    substep_verdict_columns.write(g, "verdict", substep_verdicts(s, timed));
  }
}

void read_substeps(const H5::Group& root, study& s) {
  auto& studies = s.results.put(std::vector<substep_study>{});
  const H5::Group top = root.openGroup("substeps");
  for (const auto& problem : h5::children(top)) {
    const H5::Group g = top.openGroup(problem);
    substep_study& st = studies.emplace_back();
    st.problem = problem;
    st.frame_dt = h5::double_attr(g, "frame_dt");
    const H5::Group methods = g.openGroup("methods");
    for (const auto& name : h5::children(methods)) {
      const H5::Group mg = methods.openGroup(name);
      substep_method& m = st.methods.emplace_back();
      if (const method_info* known = registered_method(name)) m.info = *known;
      m.info.name = name;
      m.info.origin = parse_enum(
          h5::string_attr(mg, "origin"),
          {method_origin::ours, method_origin::peer, method_origin::baseline, method_origin::plugin}, "method origin");
      m.info.traits.needs_jacobian = h5::long_attr(mg, "needs_jacobian") != 0;
      m.rows = substep_runs_columns().read(mg, "runs");
    }
  }
}

}  // namespace stepbench

#include "store/verdict.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/number.hpp"
#include "core/text.hpp"
#include "judge/verdict.hpp"
#include "store/columns.hpp"
#include "store/study_file.hpp"
#include "store/substeps.hpp"

namespace stepbench {

void judge_findings_again(H5::Group& root, const std::vector<std::string>& problems) {
  // What the findings read, back from the merged file: the sweep's rows and the substeps
  // studies, in the study's order of problems.
  study s;
  if (h5::long_attr(root, "timing") != 0) s.timed.emplace();
  read_problems(root, s);
  if (h5::is_group(root, "substeps")) read_substeps(root, s);
  auto* read = s.results.find<std::vector<substep_study>>();
  auto& substeps = read ? *read : s.results.put(std::vector<substep_study>{});
  std::vector<problem_study> swept;
  std::vector<substep_study> stepped;
  for (const auto& p : problems) {
    for (auto& ps : s.problems)
      if (ps.name == p) swept.push_back(std::move(ps));
    for (auto& st : substeps)
      if (st.problem == p) stepped.push_back(std::move(st));
  }
  s.problems = std::move(swept);
  substeps = std::move(stepped);
  const auto findings = findings_of(read_verdict(root), finding_inputs_of(s));
  H5::Group g = root.openGroup("verdict");
  if (g.attrExists("findings")) g.removeAttr("findings");
  h5::attr(g, "findings", fmt::format("{}", fmt::join(findings, "\n")));
}

namespace {

// A side's figure at equal error, NaN when it reaches no target.
template <class R, cost_at_error R::*side, double cost_at_error::*figure>
double figure_of(const R& e) {
  const auto& c = e.*side;
  return c.found() ? c.*figure : nan;
}
template <class R, cost_at_error R::*side, double cost_at_error::*figure>
void set_figure(R& e, double v) {
  (e.*side).*figure = v;
}

const column_map<equal_error_verdict>& equal_error_columns() {
  using R = equal_error_verdict;
  using C = cost_at_error;
  static const auto columns =
      column_map<R>("verdict_equal_error", "/verdict/equal_error")
          .member("problem", &R::problem)
          .member("unit", &R::unit)
          .member("target", &R::target)
          .member("ours_method", &R::ours, &C::method)
          .member("ours_kind", &R::ours, &C::kind)
          .field("ours_param", figure_of<R, &R::ours, &C::param>, set_figure<R, &R::ours, &C::param>)
          .field("ours_cost", figure_of<R, &R::ours, &C::cost>, set_figure<R, &R::ours, &C::cost>)
          .field("ours_cost_lo", figure_of<R, &R::ours, &C::cost_lo>, set_figure<R, &R::ours, &C::cost_lo>)
          .field("ours_cost_hi", figure_of<R, &R::ours, &C::cost_hi>, set_figure<R, &R::ours, &C::cost_hi>)
          .member("ours_interpolated", &R::ours, &C::interpolated)
          .member("peer_method", &R::peer, &C::method)
          .member("peer_kind", &R::peer, &C::kind)
          .field("peer_param", figure_of<R, &R::peer, &C::param>, set_figure<R, &R::peer, &C::param>)
          .field("peer_cost", figure_of<R, &R::peer, &C::cost>, set_figure<R, &R::peer, &C::cost>)
          .field("peer_cost_lo", figure_of<R, &R::peer, &C::cost_lo>, set_figure<R, &R::peer, &C::cost_lo>)
          .field("peer_cost_hi", figure_of<R, &R::peer, &C::cost_hi>, set_figure<R, &R::peer, &C::cost_hi>)
          .member("peer_interpolated", &R::peer, &C::interpolated)
          .member("ratio", &R::ratio)
          .member("cost_kind", &R::cost_kind)
          .member("verdict", &R::verdict)
          .member("best_error", &R::best_error)
          // Added within format 4: absent from the files written before them, read as unknown.
          .field("ours_force_evals", figure_of<R, &R::ours, &C::force_evals>, set_figure<R, &R::ours, &C::force_evals>)
          .missing_as(nan)
          .field("peer_force_evals", figure_of<R, &R::peer, &C::force_evals>, set_figure<R, &R::peer, &C::force_evals>)
          .missing_as(nan)
          .member("noise_factor", &R::noise_factor)
          .missing_as(nan)
          .member("evals_ratio", &R::evals_ratio)
          .missing_as(nan)
          .member("per_eval_ratio", &R::per_eval_ratio)
          .missing_as(nan);
  return columns;
}

const column_map<plugin_at_error>& plugin_equal_error_columns() {
  using R = plugin_at_error;
  using C = cost_at_error;
  static const auto columns =
      column_map<R>("verdict_plugin_equal_error", "/verdict/plugin_equal_error")
          .optional()
          .member("problem", &R::problem)
          .member("unit", &R::unit)
          .member("target", &R::target)
          .member("plugin_method", &R::plugin, &C::method)
          .member("plugin_kind", &R::plugin, &C::kind)
          .field("plugin_param", figure_of<R, &R::plugin, &C::param>, set_figure<R, &R::plugin, &C::param>)
          .field("plugin_cost", figure_of<R, &R::plugin, &C::cost>, set_figure<R, &R::plugin, &C::cost>)
          .field("plugin_cost_lo", figure_of<R, &R::plugin, &C::cost_lo>, set_figure<R, &R::plugin, &C::cost_lo>)
          .field("plugin_cost_hi", figure_of<R, &R::plugin, &C::cost_hi>, set_figure<R, &R::plugin, &C::cost_hi>)
          .member("plugin_interpolated", &R::plugin, &C::interpolated)
          .member("vs_ours", &R::vs_ours)
          .member("vs_peer", &R::vs_peer)
          .member("cost_kind", &R::cost_kind)
          .member("verdict_ours", &R::verdict_ours)
          .member("verdict_peer", &R::verdict_peer);
  return columns;
}

const auto frame_rate_columns = column_map<frame_stability>("verdict_frame_rate", "/verdict/frame_rate")
                                    .member("problem", &frame_stability::problem)
                                    .member("unit", &frame_stability::unit)
                                    .member("hz", &frame_stability::hz)
                                    .member("method", &frame_stability::method)
                                    .member("stable", &frame_stability::stable)
                                    .member("err_pos_max", &frame_stability::err_pos_max)
                                    .member("note", &frame_stability::note);

const auto frame_answer_columns = column_map<frame_answer>("verdict_frame_answer", "/verdict/frame_answer")
                                      .member("problem", &frame_answer::problem)
                                      .member("unit", &frame_answer::unit)
                                      .member("hz", &frame_answer::hz)
                                      .member("target", &frame_answer::target)
                                      .member("method", &frame_answer::method)
                                      .member("substeps", &frame_answer::substeps)
                                      .member("err_pos_max", &frame_answer::err_pos_max)
                                      .member("cost_per_frame", &frame_answer::cost_per_frame)
                                      .member("frame_share", &frame_answer::frame_share);

const auto frame_rate_run_columns = column_map<frame_option>("frame_rate_runs", "/frame_rates/<p>/runs")
                                        .member("hz", &frame_option::hz)
                                        .member("method", &frame_option::method)
                                        .member("substeps", &frame_option::substeps)
                                        .member("dt", &frame_option::dt)
                                        .member("completed", &frame_option::completed)
                                        .member("diverged", &frame_option::diverged)
                                        .member("err_pos_max", &frame_option::err_pos_max)
                                        .member("steps", &frame_option::steps)
                                        .member("force_evals", &frame_option::force_evals)
                                        .member("cost_per_frame", &frame_option::cost_per_frame)
                                        .member("note", &frame_option::note);

}  // namespace

std::vector<schema::table> verdict_file_tables() {
  return {equal_error_columns().spec(), plugin_equal_error_columns().spec(), frame_rate_columns.spec(),
          frame_answer_columns.spec(), frame_rate_run_columns.spec()};
}

void write_verdict(H5::Group& root, const study& s) {
  using h5::attr;
  const verdict_tables* found = s.results.find<verdict_tables>();
  if (!found) return;
  const verdict_tables& v = *found;
  H5::Group g = root.createGroup("verdict");
  attr(g, "metric", verdict_metric);
  attr(g, "targets", verdict_targets());
  attr(g, "frame_hz", s.options.frame_rates.hz);
  attr(g, "cost_kind", v.cost_kind);
  attr(g, "findings", fmt::format("{}", fmt::join(v.findings, "\n")));
  attr(g, "rule",
       "time (or force evaluations) at equal error, interpolated log-log between the two measured rows that bracket "
       "the target on each method's work-precision curve, never extrapolated; ahead or behind only when the ratio "
       "lies outside the timing noise: the larger of 15 % (25 % from one repetition) and 3 x the repetitions' "
       "relative spread, the band stepbench compare uses between two runs");
  equal_error_columns().write(g, "equal_error", v.equal_error);
  plugin_equal_error_columns().write(g, "plugin_equal_error", v.plugin_equal_error);  // optional: none without plugins
  frame_rate_columns.write(g, "frame_rate", v.frame_rate);
  frame_answer_columns.write(g, "frame_answer", v.frame_answers);
}

void write_frame_rates(H5::Group& root, const study& s) {
  using h5::attr;
  const auto& studies = s.results.get<std::vector<frame_rate_study>>();
  if (studies.empty()) return;
  H5::Group fr = root.createGroup("frame_rates");
  for (const auto& fs : studies) {
    H5::Group pg = fr.createGroup(fs.problem);
    attr(pg, "horizon", fs.horizon);
    attr(pg, "position_unit", fs.unit);
    frame_rate_run_columns.write(pg, "runs", frame_options(s, fs));
  }
}

void read_frame_rates(const H5::Group& root, study& s) {
  auto& studies = s.results.put(std::vector<frame_rate_study>{});
  const H5::Group all = root.openGroup("frame_rates");
  for (const auto& problem : h5::children(all)) {
    const H5::Group g = all.openGroup(problem);
    frame_rate_study& fs = studies.emplace_back();
    fs.problem = problem;
    fs.unit = h5::string_attr(g, "position_unit");
    fs.horizon = h5::double_attr(g, "horizon");
    // The run as the file keeps it: a run that did not complete and did not diverge
    // failed (or was skipped: the file does not tell them apart); its cost a frame is
    // derived again from the sweep's rows (frame_options).
    for (const frame_option& o : frame_rate_run_columns.read(g, "runs")) {
      frame_rate_run& r = fs.runs.emplace_back();
      r.hz = o.hz;
      r.method = o.method;
      r.substeps = o.substeps;
      r.row.param = o.dt;
      r.row.steps = o.steps;
      r.row.work.force_evals = static_cast<long>(o.force_evals);
      r.row.metrics.err_pos_max = o.err_pos_max;
      r.row.metrics.diverged = o.diverged;
      r.row.metrics.failed = !o.completed && !o.diverged;
      r.row.metrics.note = o.note;
    }
  }
}

verdict_tables read_verdict(const H5::Group& root) {
  if (!h5::is_group(root, "verdict"))
    throw std::runtime_error("it has no /verdict (written before format_version 4: run the study again)");
  const H5::Group g = root.openGroup("verdict");
  verdict_tables v;
  v.cost_kind = h5::string_attr(g, "cost_kind");
  v.findings = stored_list(h5::string_attr(g, "findings"), '\n');  // a finding is one sentence, never empty
  v.equal_error = equal_error_columns().read(g, "equal_error");
  v.plugin_equal_error = plugin_equal_error_columns().read(g, "plugin_equal_error");
  v.frame_rate = frame_rate_columns.read(g, "frame_rate");
  v.frame_answers = frame_answer_columns.read(g, "frame_answer");
  return v;
}

}  // namespace stepbench

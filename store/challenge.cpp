#include "store/challenge.hpp"

#include "store/columns.hpp"

namespace stepbench {
namespace {

using criterion_verdict = std::pair<std::string, std::string>;

const auto entry_columns = column_map<challenge_entry>("challenge_entries", "/challenge/entries")
                               .member("method", &challenge_entry::method)
                               .member("steps_per_frame", &challenge_entry::steps_per_frame)
                               .member("tolerance", &challenge_entry::tolerance)
                               .member("ns_per_frame", &challenge_entry::ns_per_frame)
                               .member("err_pos_max", &challenge_entry::err_pos_max)
                               .member("energy_drift", &challenge_entry::energy_drift)
                               .member("energy_err_max", &challenge_entry::energy_err_max)
                               .member("link_err_max", &challenge_entry::link_err_max)
                               .member("stable", &challenge_entry::stable)
                               .member("ns_per_frame_at_xpbd_error", &challenge_entry::ns_per_frame_at_xpbd_error)
                               .member("note", &challenge_entry::note);

const auto verdict_columns = column_map<criterion_verdict>("challenge_verdicts", "/challenge/verdicts")
                                 .member("criterion", &criterion_verdict::first)
                                 .member("verdict", &criterion_verdict::second);

const auto small_steps_columns = column_map<small_steps_row>("small_steps", "/challenge/small_steps")
                                     .member("problem", &small_steps_row::problem)
                                     .member("design", &small_steps_row::design)
                                     .member("n", &small_steps_row::n)
                                     .member("err_pos", &small_steps_row::err_pos)
                                     .member("link_err", &small_steps_row::link_err)
                                     .member("work_per_frame", &small_steps_row::work_per_frame)
                                     .member("ns_per_frame", &small_steps_row::ns_per_frame)
                                     .member("diverged", &small_steps_row::diverged);

}  // namespace

std::vector<schema::table> challenge_tables() {
  return {entry_columns.spec(), verdict_columns.spec(), small_steps_columns.spec()};
}

void write_challenge(H5::Group& root, const challenge_result& r) {
  H5::Group g = root.createGroup("challenge");
  h5::attr(g, "hz", r.options.hz);
  h5::attr(g, "xpbd_substeps", r.options.xpbd_substeps);
  h5::attr(g, "horizon", r.options.horizon);
  h5::attr(g, "energy_horizon", r.options.energy_horizon);
  h5::attr(g, "small_steps_time", r.options.small_steps_time);
  h5::attr(g, "energy_scale", r.energy_scale);
  h5::attr(g, "wall_seconds", r.seconds);
  entry_columns.write(g, "entries", r.entries);
  std::vector<criterion_verdict> lines;
  for (std::size_t i = 0; i < r.verdicts.size(); ++i) lines.emplace_back(r.verdict_criteria[i], r.verdicts[i]);
  for (const auto& v : r.small_steps_verdicts) lines.emplace_back("small_steps", v);
  verdict_columns.write(g, "verdicts", lines);
  small_steps_columns.write(g, "small_steps", r.small_steps);
}

}  // namespace stepbench

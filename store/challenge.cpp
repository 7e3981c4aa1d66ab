#include "store/challenge.hpp"

#include "store/columns.hpp"

namespace stepbench {
namespace {

using criterion_verdict = std::pair<std::string, std::string>;

const column_map<challenge_entry>& entry_columns() {
  using E = challenge_entry;
  static const auto entries = column_map<E>("challenge_entries", "/challenge/entries")
                                  .member("method", &E::method)
                                  .member("steps_per_frame", &E::steps_per_frame)
                                  .member("tolerance", &E::tolerance)
                                  .member("ns_per_frame", &E::ns_per_frame)
                                  .member("err_pos_max", &E::err_pos_max)
                                  .member("energy_drift", &E::energy_drift)
                                  .member("energy_err_max", &E::energy_err_max)
                                  .member("link_err_max", &E::link_err_max)
                                  .member("stable", &E::stable)
                                  .member("ns_per_frame_at_xpbd_error", &E::ns_per_frame_at_xpbd_error)
                                  .member("note", &E::note);
  return entries;
}

const column_map<criterion_verdict>& verdict_columns() {
  using V = criterion_verdict;
  static const auto verdicts = column_map<V>("challenge_verdicts", "/challenge/verdicts")
                                   .member("criterion", &V::first)
                                   .member("verdict", &V::second);
  return verdicts;
}

const column_map<small_steps_row>& small_steps_columns() {
  using S = small_steps_row;
  static const auto small_steps = column_map<S>("small_steps", "/challenge/small_steps")
                                      .member("problem", &S::problem)
                                      .member("design", &S::design)
                                      .member("n", &S::n)
                                      .member("err_pos", &S::err_pos)
                                      .member("link_err", &S::link_err)
                                      .member("work_per_frame", &S::work_per_frame)
                                      .member("ns_per_frame", &S::ns_per_frame)
                                      .member("diverged", &S::diverged);
  return small_steps;
}

}  // namespace

std::vector<schema::table> challenge_tables() {
  return {entry_columns().spec(), verdict_columns().spec(), small_steps_columns().spec()};
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
  entry_columns().write(g, "entries", r.entries);
  std::vector<criterion_verdict> lines;
  for (std::size_t i = 0; i < r.verdicts.size(); ++i) lines.emplace_back(r.verdict_criteria[i], r.verdicts[i]);
  for (const auto& v : r.small_steps_verdicts) lines.emplace_back("small_steps", v);
  verdict_columns().write(g, "verdicts", lines);
  small_steps_columns().write(g, "small_steps", r.small_steps);
}

}  // namespace stepbench

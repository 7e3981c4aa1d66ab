#include "store/challenge.hpp"

#include "store/columns.hpp"

namespace stepbench {

void write_challenge(H5::Group& root, const challenge_result& r) {
  H5::Group g = root.createGroup("challenge");
  h5::attr(g, "hz", r.options.hz);
  h5::attr(g, "xpbd_substeps", r.options.xpbd_substeps);
  h5::attr(g, "horizon", r.options.horizon);
  h5::attr(g, "energy_horizon", r.options.energy_horizon);
  h5::attr(g, "small_steps_time", r.options.small_steps_time);
  h5::attr(g, "energy_scale", r.energy_scale);
  h5::attr(g, "wall_seconds", r.seconds);
  using E = challenge_entry;
  static const auto entries = column_map<E>("challenge_entries")
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
  entries.write(g, "entries", r.entries);
  using V = std::pair<std::string, std::string>;
  static const auto verdicts =
      column_map<V>("challenge_verdicts").member("criterion", &V::first).member("verdict", &V::second);
  std::vector<V> lines;
  for (std::size_t i = 0; i < r.verdicts.size(); ++i) lines.emplace_back(r.verdict_criteria[i], r.verdicts[i]);
  for (const auto& v : r.small_steps_verdicts) lines.emplace_back("small_steps", v);
  verdicts.write(g, "verdicts", lines);
  using S = small_steps_row;
  static const auto small_steps = column_map<S>("small_steps")
                                      .member("problem", &S::problem)
                                      .member("design", &S::design)
                                      .member("n", &S::n)
                                      .member("err_pos", &S::err_pos)
                                      .member("link_err", &S::link_err)
                                      .member("work_per_frame", &S::work_per_frame)
                                      .member("ns_per_frame", &S::ns_per_frame)
                                      .member("diverged", &S::diverged);
  small_steps.write(g, "small_steps", r.small_steps);
}

}  // namespace stepbench

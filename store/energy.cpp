#include "store/energy.hpp"

#include "store/h5.hpp"
#include "store/schema.hpp"
#include "store/study_file.hpp"

namespace stepbench {

void write_energy(H5::Group& root, const energy_study& s) {
  if (s.problems.empty()) return;
  using h5::attr;
  H5::Group g = root.createGroup("energy");
  const auto& o = s.options;
  attr(g, "periods", o.periods);
  attr(g, "samples_per_period", o.samples_per_period);
  attr(g, "series_points", o.series_points);
  attr(g, "bounded_growth", o.bounded_growth);
  attr(g, "lost", o.lost);
  attr(g, "rule",
       fmt::format("bounded: the largest |E - E0| / |E0| over the last tenth of the run is at most {:g} times the "
                   "largest over the first tenth, and every error is below {:g}; drifting otherwise, its sign that "
                   "of the mean error over the last tenth",
                   o.bounded_growth, o.lost));
  attr(g, "wall_seconds", s.wall_seconds);
  for (const auto& ep : s.problems) {
    H5::Group pg = g.createGroup(ep.problem);
    parameters_table(ep.params).write(pg, "parameters", schema::find("parameters"));
    attr(pg, "period", ep.period);
    attr(pg, "dt", ep.dt);
    attr(pg, "steps_per_period", ep.steps_per_period);
    attr(pg, "horizon", ep.horizon);
    attr(pg, "energy0", ep.e0);
    attr(pg, "angular_momentum0", ep.l0);
    h5::table t;
    auto col = [&](auto get) {
      using T = decltype(get(ep.runs.front()));
      std::vector<T> v;
      for (const auto& r : ep.runs) v.push_back(get(r));
      return v;
    };
    t.add("method", col([](const energy_run& r) { return r.info.name; }));
    t.add("symplectic", col([](const energy_run& r) { return static_cast<std::int8_t>(r.info.traits.symplectic); }));
    t.add("dt", col([](const energy_run& r) { return r.dt; }));
    t.add("steps", col([](const energy_run& r) { return std::int64_t{r.steps}; }));
    t.add("force_evals", col([](const energy_run& r) { return std::int64_t{r.force_evals}; }));
    t.add("completed", col([](const energy_run& r) { return static_cast<std::int8_t>(r.completed); }));
    t.add("max_rel_err", col([](const energy_run& r) { return r.max_rel_err; }));
    t.add("final_rel_err", col([](const energy_run& r) { return r.final_rel_err; }));
    t.add("drift_per_period", col([](const energy_run& r) { return r.drift_per_period; }));
    t.add("first_tenth_max", col([](const energy_run& r) { return r.first_tenth_max; }));
    t.add("last_tenth_max", col([](const energy_run& r) { return r.last_tenth_max; }));
    t.add("last_tenth_mean", col([](const energy_run& r) { return r.last_tenth_mean; }));
    t.add("verdict", col([](const energy_run& r) { return r.verdict; }));
    t.add("drift_sign", col([](const energy_run& r) { return std::int64_t{r.drift_sign}; }));
    t.add("angmom_max_rel_err", col([](const energy_run& r) { return r.angmom_max_rel_err; }));
    t.add("angmom_drift_per_period", col([](const energy_run& r) { return r.angmom_drift_per_period; }));
    t.add("seconds", col([](const energy_run& r) { return r.seconds; }));
    t.add("note", col([](const energy_run& r) { return r.note; }));
    t.write(pg, "summary", schema::find("energy_summary"));
    H5::Group series = pg.createGroup("series");
    for (const auto& r : ep.runs) {
      if (!r.completed) continue;
      H5::Group mg = series.createGroup(r.info.name);
      h5::dataset(mg, "time", r.series_t);
      h5::dataset(mg, "energy_error", r.series_err);
    }
  }
}

}  // namespace stepbench

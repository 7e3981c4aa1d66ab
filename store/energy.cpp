#include "store/energy.hpp"

#include "store/h5.hpp"
#include "store/schema.hpp"
#include "store/study_file.hpp"

namespace stepbench {

namespace {

const auto energy_columns =
    column_map<energy_run>("energy_summary", "/energy/<p>/summary")
        .member("method", &energy_run::info, &method_info::name)
        .member("symplectic", &energy_run::info, &method_info::traits, &capabilities::symplectic)
        .member("dt", &energy_run::dt)
        .member("steps", &energy_run::steps)
        .member("force_evals", &energy_run::force_evals)
        .member("completed", &energy_run::completed)
        .member("max_rel_err", &energy_run::max_rel_err)
        .member("final_rel_err", &energy_run::final_rel_err)
        .member("drift_per_period", &energy_run::drift_per_period)
        .member("first_tenth_max", &energy_run::first_tenth_max)
        .member("last_tenth_max", &energy_run::last_tenth_max)
        .member("last_tenth_mean", &energy_run::last_tenth_mean)
        .member("verdict", &energy_run::verdict)
        .member("drift_sign", &energy_run::drift_sign)
        .member("angmom_max_rel_err", &energy_run::angmom_max_rel_err)
        .member("angmom_drift_per_period", &energy_run::angmom_drift_per_period)
        .member("seconds", &energy_run::seconds)
        .member("note", &energy_run::note);

}  // namespace

std::vector<schema::table> energy_tables() { return {energy_columns.spec()}; }

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
    parameters_columns().write(pg, "parameters", ep.params);
    attr(pg, "period", ep.period);
    attr(pg, "dt", ep.dt);
    attr(pg, "steps_per_period", ep.steps_per_period);
    attr(pg, "horizon", ep.horizon);
    attr(pg, "energy0", ep.e0);
    attr(pg, "angular_momentum0", ep.l0);
    energy_columns.write(pg, "summary", ep.runs);
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

#include "store/stability.hpp"

#include "store/h5.hpp"

namespace stepbench {

const column_map<stability_limit>& stability_limit_columns() {
  using R = stability_limit;
  static const auto columns =
      column_map<R>("stability_limits", "/stability/limits")
          .member("integrator", &R::integrator)
          .field(
              "test", [](const R& l) { return std::string(to_string(l.test)); },
              [](R& l, const std::string& test) {
                l.test = parse_enum(test, {stability_test::oscillator, stability_test::decay}, "stability test");
              })
          .member("measured", &R::measured)
          .member("theory", &R::theory)
          .derived("rel_difference", [](const R& l) { return l.rel_difference(); })
          .member("unstable_for_all_dt", &R::unstable_for_all_dt)
          .member("unconditionally_stable", &R::unconditionally_stable)
          .member("run_confirms", &R::run_confirms)
          .member("step_failed_at", &R::step_failed_at)
          .member("note", &R::note);
  return columns;
}

std::vector<schema::table> stability_tables() { return {stability_limit_columns().spec()}; }

void write_stability(H5::Group& root, const stability_data& d) {
  using h5::attr;
  const auto& s = d.settings;
  H5::Group g = root.createGroup("stability");
  attr(g, "oscillator", "x'' = -omega^2 x as F = -m omega^2 x; y = omega dt; initial (x, v) = (1, 0)");
  attr(g, "decay",
       "pure damper F = -m lambda v, so v' = -lambda v and x integrates v; y = lambda dt; initial "
       "(x, v) = (0, 1)");
  attr(g, "adaptive_tolerance", always_accept_tolerance);
  attr(g, "y_min", s.y_min);
  attr(g, "y_max", s.y_max);
  attr(g, "y_unconditional", s.y_unconditional);
  attr(g, "per_decade", s.per_decade);
  attr(g, "rho_tol", s.rho_tol);
  attr(g, "clear_factor", s.clear_factor);
  attr(g, "root_rtol", s.root_rtol);
  attr(g, "run_steps", s.run_steps);
  attr(g, "envelope_growth", s.envelope_growth);
  attr(g, "blowup_factor", s.blowup_factor);
  attr(g, "decay_floor", s.decay_floor);
  attr(g, "run_y_start", s.run_y_start);
  attr(g, "run_per_decade", s.run_per_decade);
  attr(g, "run_rtol", s.run_rtol);
  attr(g, "confirm_y", s.confirm_y);
  attr(g, "agreement", s.agreement);
  attr(g, "region_dt", 1.0);
  attr(g, "limits_seconds", d.limits_seconds);
  attr(g, "regions_seconds", d.regions_seconds);

  stability_limit_columns().write(g, "limits", d.limits);

  const auto& r = d.regions;
  h5::dataset(g, "region_re", r.re);
  h5::dataset(g, "region_im", r.im);
  H5::Group regions = g.createGroup("regions");
  for (std::size_t k = 0; k < r.integrators.size(); ++k) {
    std::vector<std::vector<double>> rows(r.im.size());
    for (std::size_t i = 0; i < r.im.size(); ++i)
      rows[i].assign(r.abs_r[k].begin() + static_cast<std::ptrdiff_t>(i * r.re.size()),
                     r.abs_r[k].begin() + static_cast<std::ptrdiff_t>((i + 1) * r.re.size()));
    h5::compressed_grid(regions, r.integrators[k], rows);
  }
}

}  // namespace stepbench

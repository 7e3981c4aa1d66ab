#include "store/stability.hpp"

#include "store/h5.hpp"
#include "store/schema.hpp"

namespace stepbench {

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

  h5::table t;
  auto col = [&](auto get) {
    using T = decltype(get(d.limits.front()));
    std::vector<T> v;
    for (const auto& l : d.limits) v.push_back(get(l));
    return v;
  };
  t.add("integrator", col([](const stability_limit& l) { return l.integrator; }));
  t.add("test", col([](const stability_limit& l) { return std::string(to_string(l.test)); }));
  t.add("measured", col([](const stability_limit& l) { return l.measured; }));
  t.add("theory", col([](const stability_limit& l) { return l.theory; }));
  t.add("rel_difference", col([](const stability_limit& l) { return l.rel_difference(); }));
  t.add("unstable_for_all_dt",
        col([](const stability_limit& l) { return static_cast<std::int8_t>(l.unstable_for_all_dt); }));
  t.add("unconditionally_stable",
        col([](const stability_limit& l) { return static_cast<std::int8_t>(l.unconditionally_stable); }));
  t.add("run_confirms", col([](const stability_limit& l) { return static_cast<std::int8_t>(l.run_confirms); }));
  t.add("step_failed_at", col([](const stability_limit& l) { return l.step_failed_at; }));
  t.add("note", col([](const stability_limit& l) { return l.note; }));
  t.write(g, "limits", schema::find("stability_limits"));

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

// `stepbench stability [--json]`: the stability limits of our integrators on the
// undamped oscillator and on pure decay, from their compiled steps (study/stability.hpp):
// (a) from the amplification matrix of one step, (b) from long runs, and whether a method
// is unstable for every dt or unconditionally stable. The study file carries the same
// figures and the stability regions under /stability.
#include "run/stability.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "core/work_precision.hpp"
#include "render/table_render.hpp"
#include "study/stability.hpp"

namespace stepbench {
inline void to_json(nlohmann::json& j, stability_test t) { j = to_string(t); }
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(stability_limit, integrator, test, measured, theory, unstable_for_all_dt,
                                   unconditionally_stable, run_confirms, step_failed_at, note)
}  // namespace stepbench

namespace stepbench::cli {
namespace {

int run_stability(bool as_json) {
  const stability_data d = compute_stability();
  if (as_json) {
    std::cout << nlohmann::json(d.limits).dump(2) << "\n";  // NaN is written as null
    return 0;
  }
  const auto& s = d.settings;
  fmt::print("Stability limits of our integrators, from their compiled steps\n");
  fmt::print("  oscillator: x'' = -omega^2 x (F = -m omega^2 x), y = omega dt\n");
  fmt::print("  decay:      pure damper F = -m lambda v (v' = -lambda v; x integrates v), y = lambda dt\n");
  fmt::print("  theory (a):   root of rho(M(y)) - 1 - {:g}, M the amplification matrix of one step\n", s.rho_tol);
  fmt::print(
      "  measured (b): bisection on runs of {} steps, unstable when the largest |state| of the second half\n"
      "                exceeds {:g} x that of the first half (or passes {:g} x the start)\n",
      s.run_steps, s.envelope_growth, s.blowup_factor);
  fmt::print("  adaptive methods: the step they take when every attempt is accepted (tolerance {:g})\n\n",
             always_accept_tolerance);
  table t{{"integrator", "test", right_column("y_max theory (a)"), right_column("y_max measured (b)"),
           right_column("(b)/(a)-1"), "long runs"},
          {}};
  for (const auto& l : d.limits) {
    // A method unstable, or stable, for every dt has no limit to measure.
    const bool limit = !l.unstable_for_all_dt && !l.unconditionally_stable;
    const std::string theory = l.unstable_for_all_dt      ? "unstable"
                               : l.unconditionally_stable ? "uncond."
                               : std::isfinite(l.theory)  ? fmt::format("{:.6f}", l.theory)
                                                          : "no verdict";
    t.add({l.integrator, std::string(to_string(l.test)), theory,
           limit && std::isfinite(l.measured) ? fmt::format("{:.6f}", l.measured) : "-",
           limit && std::isfinite(l.rel_difference()) ? fmt::format("{:+.1e}", l.rel_difference()) : "-",
           (l.run_confirms ? "" : "NOT CONFIRMED: ") + l.note});
  }
  fmt::print("{}", render_text(t, ""));
  fmt::print("\n\"unstable\": unstable for every dt; \"uncond.\": stable for every dt (up to y = {:g}).\n",
             s.y_unconditional);
  fmt::print("Computed in {} (limits {}, stability regions on a {} x {} grid {}).\n",
             format_time_ns((d.limits_seconds + d.regions_seconds) * 1e9), format_time_ns(d.limits_seconds * 1e9),
             s.re_count, s.im_count, format_time_ns(d.regions_seconds * 1e9));
  return 0;
}

}  // namespace

command add_stability(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "stability", "stability limits of our integrators on the oscillator and on decay, from their steps");
  auto as_json = std::make_shared<bool>(false);
  sub->add_flag("--json", *as_json, "print JSON: one record per integrator and test");
  return {sub, [as_json] { return run_stability(*as_json); }};
}

}  // namespace stepbench::cli

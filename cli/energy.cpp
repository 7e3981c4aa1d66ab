// `stepbench energy [--json]`: the long-run energy study (study/energy.hpp): every
// fixed-step integrator of ours on pendulum and kepler for 10^4 periods at a stated dt,
// its largest energy error, its drift per period, bounded or drifting (with the sign),
// and on kepler the angular momentum. The study file carries the same under /energy.
#include "run/energy.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/work_precision.hpp"
#include "render/table_render.hpp"
#include "study/energy.hpp"

namespace stepbench {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(energy_run, dt, steps, force_evals, completed, max_rel_err, final_rel_err,
                                   drift_per_period, verdict, drift_sign, angmom_max_rel_err, angmom_drift_per_period,
                                   note)
}  // namespace stepbench

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct energy_args {
  bool json = false;
  double periods = 1e4;
  std::vector<std::string> problems, sets;
};

std::string sci(double v) { return std::isfinite(v) ? fmt::format("{:.2e}", v) : "-"; }
std::string signed_sci(double v) { return std::isfinite(v) ? fmt::format("{:+.2e}", v) : "-"; }

int run_energy(const energy_args& a) {
  energy_options opts;
  opts.periods = a.periods;
  if (!a.problems.empty()) {
    std::vector<energy_scene> chosen;
    for (const auto& name : a.problems) {
      bool found = false;
      for (const auto& s : opts.scenes)
        if (s.problem == name) chosen.push_back(s), found = true;
      if (!found)
        throw std::invalid_argument(fmt::format("the energy study runs on pendulum and kepler, not {}", name));
    }
    opts.scenes = chosen;
  }
  parameter_overrides overrides;
  std::vector<std::string> names;
  for (const auto& s : opts.scenes) names.push_back(s.problem);
  for (const auto& s : a.sets) add_override(overrides, s, names);
  opts.progress = !a.json;
  const energy_study s = run_energy_study(opts, overrides);
  if (a.json) {
    json out = json::array();
    for (const auto& p : s.problems)
      for (const auto& r : p.runs) {
        json run = r;  // NaN is written as null
        run.update({{"problem", p.problem},
                    {"method", r.info.name},
                    {"symplectic", r.info.traits.symplectic},
                    {"steps_per_period", p.steps_per_period},
                    {"periods", opts.periods}});
        out.push_back(std::move(run));
      }
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  for (const auto& p : s.problems) {
    fmt::print("{}: {:g} periods of {:.6g} s, dt = {:.6g} s ({} a period); E0 = {:.6g} J{}\n", p.problem, opts.periods,
               p.period, p.dt, count_of(p.steps_per_period, "step"), p.e0,
               std::isfinite(p.l0) ? fmt::format(", L0 = {:.6g} kg m^2/s", p.l0) : "");
    // Relative errors (dE/E, dL/L: no unit); the drifts per period of the problem.
    table t{{"method", right_column("max |dE|/E"), right_column("final dE/E"), right_column("dE/E drift", "1/period"),
             "verdict", right_column("max |dL|/L"), right_column("dL/L drift", "1/period")},
            {}};
    std::vector<std::string> failures;  // below the table: a long reason would stretch its column
    for (const auto& r : p.runs) {
      const std::string verdict = !r.completed       ? "failed (below)"
                                  : r.drift_sign > 0 ? "drifting, gains"
                                  : r.drift_sign < 0 ? "drifting, loses"
                                                     : r.verdict;
      if (!r.completed) failures.push_back(fmt::format("  {} failed: {}\n", r.info.name, r.note));
      t.add({r.info.name, sci(r.max_rel_err), signed_sci(r.final_rel_err), signed_sci(r.drift_per_period), verdict,
             sci(r.angmom_max_rel_err), signed_sci(r.angmom_drift_per_period)});
    }
    fmt::print("{}", render_text(t));
    for (const auto& f : failures) fmt::print("{}", f);
  }
  fmt::print(
      "bounded: the largest |dE|/E over the last tenth of the run is at most {:g} x that over the first tenth, "
      "and below {:g}; drifting otherwise.\n",
      opts.bounded_growth, opts.lost);
  std::fflush(stdout);
  fmt::print(stderr, "energy study in {}\n", format_time_ns(s.wall_seconds * 1e9));
  return 0;
}

}  // namespace

command add_energy(CLI::App& app) {
  auto a = std::make_shared<energy_args>();
  auto* sub = app.add_subcommand("energy", "long-run energy of the fixed-step integrators on pendulum and kepler");
  sub->add_flag("--json", a->json, "print JSON: one record per problem and integrator");
  sub->add_option("--periods", a->periods, "periods to run (whole number)")->capture_default_str();
  sub->add_option("--problem", a->problems, "pendulum and/or kepler (repeatable; default both)");
  sub->add_option("--set", a->sets,
                  "override a parameter, problem.name=value, or name=value with one --problem (repeatable)");
  return {sub, [a] { return run_energy(*a); }};
}

}  // namespace stepbench::cli

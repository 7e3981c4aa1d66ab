// `stepbench energy [--json]`: the long-run energy study (study/energy.hpp): every
// fixed-step integrator of ours on pendulum and kepler for 10^4 periods at a stated dt,
// its largest energy error, its drift per period, bounded or drifting (with the sign),
// and on kepler the angular momentum. The study file carries the same under /energy.
#include "run/energy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/work_precision.hpp"
#include "registry/registry.hpp"
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
  std::optional<double> period;
  int steps_per_period = 64;
  bool steps_given = false;
  std::vector<std::string> problems, sets;
};

std::string sci(double v) { return std::isfinite(v) ? fmt::format("{:.2e}", v) : "-"; }
std::string signed_sci(double v) { return std::isfinite(v) ? fmt::format("{:+.2e}", v) : "-"; }

int run_energy(const energy_args& a) {
  energy_options opts;
  opts.periods = a.periods;
  if (a.period && !(std::isfinite(*a.period) && *a.period > 0.0))
    throw std::invalid_argument(fmt::format("--period must be a time > 0 s, got {:g}", *a.period));
  if (a.steps_given && (a.steps_per_period < 1 || a.steps_per_period % opts.samples_per_period != 0))
    throw std::invalid_argument(fmt::format("--steps-per-period must be a positive multiple of {}, got {}",
                                            opts.samples_per_period, a.steps_per_period));
  if (!a.problems.empty()) {
    // pendulum and kepler as the study sets them up; any other problem with an energy (a
    // built-in or a scene file's) at --steps-per-period steps of --period, by default its
    // horizon (a scene has no period of its own).
    std::vector<energy_scene> chosen;
    for (const auto& name : a.problems) {
      const auto known = std::find_if(opts.scenes.begin(), opts.scenes.end(),
                                      [&](const energy_scene& s) { return s.problem == name; });
      energy_scene s;
      if (known != opts.scenes.end())
        s = *known;
      else
        s.problem = name;
      const auto p = make_problem(name);  // names an unknown problem
      if (std::isfinite(p->period()) && a.period)
        throw std::invalid_argument(fmt::format("problem {} has a period of its own; leave out --period", name));
      if (a.period) s.period = *a.period;  // else the study takes the horizon, as --set leaves it
      chosen.push_back(s);
    }
    opts.scenes = chosen;
  } else if (a.period) {
    throw std::invalid_argument(
        "--period is for a problem without a period of its own: give it with --problem or --scene");
  }
  if (a.steps_given)
    for (auto& s : opts.scenes) s.steps_per_period = a.steps_per_period;
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
    const bool own_period = std::isfinite(make_problem(p.problem)->period());
    fmt::print("{}: {:g} periods of {:.6g} s{}, dt = {:.6g} s ({} a period); E0 = {:.6g} J{}\n", p.problem,
               opts.periods, p.period, own_period ? "" : " (no period of its own: --period, default the horizon)", p.dt,
               count_of(p.steps_per_period, "step"), p.e0,
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
  auto* sub = app.add_subcommand(
      "energy",
      "long-run energy of the fixed-step integrators on pendulum and kepler, or any problem or scene with one");
  sub->add_flag("--json", a->json, "print JSON: one record per problem and integrator");
  sub->add_option("--periods", a->periods, "periods to run (whole number)")->capture_default_str();
  sub->add_option("--problem", a->problems,
                  "a problem with an energy (repeatable; default pendulum and kepler); --scene FILE for a scene file");
  sub->add_option("--period", a->period,
                  "the drift's time unit for a problem without a period of its own [s] (default its horizon)");
  sub->add_option("--steps-per-period", a->steps_per_period,
                  "fixed steps a period (a multiple of 32; default 64, kepler's 1024)")
      ->each([a](const std::string&) { a->steps_given = true; });
  sub->add_option("--set", a->sets,
                  "override a parameter, problem.name=value, or name=value with one --problem (repeatable)");
  return {sub, [a] { return run_energy(*a); }};
}

}  // namespace stepbench::cli

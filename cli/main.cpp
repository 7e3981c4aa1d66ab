// stepbench: the command line. `list`, `run` and `sweep`; every error is one line on
// stderr and a non-zero exit, and a results file is written whole or not at all.
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/advise.hpp"
#include "core/drive.hpp"
#include "core/measure.hpp"
#include "core/parse.hpp"
#include "core/registry.hpp"
#include "core/study_file.hpp"
#include "core/sweep.hpp"

using namespace stepbench;
using json = nlohmann::json;

namespace {

struct usage_error : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

int cmd_list(bool as_json) {
  json out;
  for (const auto& name : problem_names()) {
    auto p = make_problem(name);
    json params = json::array();
    for (const auto& q : p->params())
      params.push_back({{"name", q.name}, {"default", q.value}, {"unit", q.unit}, {"description", q.description}});
    out["problems"].push_back({{"name", name},
                               {"description", p->description()},
                               {"dim", p->dim()},
                               {"position_unit", p->position_unit()},
                               {"horizon", p->horizon()},
                               {"closed_form", p->has_closed_form()},
                               {"energy", p->has_energy()},
                               {"parameters", params}});
  }
  for (const auto& i : integrators())
    out["integrators"].push_back({{"name", i.name}, {"expected_order", i.order}, {"description", i.description}});
  if (as_json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  fmt::print("problems:\n");
  for (const auto& p : out["problems"]) {
    fmt::print("  {:<22} {} (dim {}, horizon {:.6g} s{})\n", p["name"].get<std::string>(),
               p["description"].get<std::string>(), p["dim"].get<int>(), p["horizon"].get<double>(),
               p["closed_form"].get<bool>() ? ", closed form" : "");
    for (const auto& q : p["parameters"])
      fmt::print("      {:<12} = {:<10g} [{}] {}\n", q["name"].get<std::string>(), q["default"].get<double>(),
                 q["unit"].get<std::string>(), q["description"].get<std::string>());
  }
  fmt::print("integrators:\n");
  for (const auto& i : out["integrators"])
    fmt::print("  {:<22} order {}  {}\n", i["name"].get<std::string>(), i["expected_order"].get<int>(),
               i["description"].get<std::string>());
  return 0;
}

struct run_args {
  std::string problem, integrator, dt_text, horizon_text;
  std::vector<std::string> sets;
  bool json = false;
};

int cmd_run(const run_args& a) {
  auto problem = make_problem(a.problem);
  find_integrator(a.integrator);
  for (const auto& s : a.sets) {
    const auto [name, value] = parse_assignment(s);
    problem->set(name, value);
  }
  if (auto err = problem->validate(); !err.empty()) throw usage_error(fmt::format("problem {}: {}", a.problem, err));
  const double dt = parse_number(a.dt_text, "--dt");
  if (!(dt > 0.0)) throw usage_error(fmt::format("--dt must be > 0, got {}", a.dt_text));
  double horizon = problem->horizon();
  if (!a.horizon_text.empty()) {
    horizon = parse_number(a.horizon_text, "--horizon");
    if (!(horizon > 0.0)) throw usage_error(fmt::format("--horizon must be > 0, got {}", a.horizon_text));
  }
  if (horizon / dt > 1e9) throw usage_error(fmt::format("--dt {} needs more than 1e9 steps to reach {}", dt, horizon));

  constexpr int sample_count = 32;
  const auto steps = sample_steps(horizon, dt, sample_count);
  const run_result run = problem->run(a.integrator, dt, horizon, steps);
  // The truth at this run's own sample times (the steps nearest j T / 32).
  std::vector<double> times;
  for (long i : steps) times.push_back(time_after_step(i, run.steps_planned, dt, horizon));
  truth_options topts;
  topts.run_references = !problem->has_closed_form();
  const truth_table truth = build_truth(*problem, times, topts);
  const run_metrics m = measure(*problem, run, truth);

  json out = {{"problem", a.problem},
              {"integrator", a.integrator},
              {"dt", dt},
              {"horizon", horizon},
              {"steps", run.steps},
              {"force_evals", run.force_evals},
              {"position", run.position},
              {"velocity", run.velocity},
              {"err_pos_final", m.err_pos_final},
              {"err_vel_final", m.err_vel_final},
              {"err_pos_max", m.err_pos_max},
              {"err_pos_rms", m.err_pos_rms},
              {"energy_drift", m.energy_drift},
              {"diverged", m.diverged},
              {"truth_source", truth.source}};
  if (m.diverged) out["diverged_reason"] = m.diverged_reason;
  const auto& y = truth.y.back();
  const int dim = problem->dim();
  out["true_position"] = std::vector<double>(y.begin(), y.begin() + dim);
  out["true_velocity"] = std::vector<double>(y.begin() + dim, y.end());
  if (a.json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  fmt::print("{} with {}: dt {:g} s to t = {:g} s, {} steps, {} force evaluations\n", a.problem, a.integrator, dt, horizon,
             run.steps, run.force_evals);
  fmt::print("  position       {::.12g}   (true {::.12g}, from {})\n", run.position, out["true_position"].get<std::vector<double>>(),
             truth.source);
  fmt::print("  velocity       {::.12g}   (true {::.12g})\n", run.velocity, out["true_velocity"].get<std::vector<double>>());
  fmt::print("  err_pos_final  {:.6e}\n  err_vel_final  {:.6e}\n  err_pos_max    {:.6e}\n  err_pos_rms    {:.6e}\n",
             m.err_pos_final, m.err_vel_final, m.err_pos_max, m.err_pos_rms);
  if (problem->has_energy()) fmt::print("  energy_drift   {:+.6e} (relative, at the horizon)\n", m.energy_drift);
  if (m.diverged) fmt::print("  DIVERGED: {}\n", m.diverged_reason);
  return 0;
}

struct sweep_args {
  sweep_options opts;
  std::vector<std::string> sets;
  std::string out = "results/study.h5";
  bool quiet = false;
};

int cmd_sweep(sweep_args a) {
  for (const auto& s : a.sets) {
    auto [name, value] = parse_assignment(s);
    std::string problem;
    if (const auto dot = name.find('.'); dot != std::string::npos) {
      problem = name.substr(0, dot);
      name = name.substr(dot + 1);
    } else if (a.opts.problems.size() == 1) {
      problem = a.opts.problems.front();
    } else {
      throw usage_error(fmt::format("--set {}: name the problem (problem.{}=value) or select one --problem", s, name));
    }
    a.opts.overrides[problem][name] = value;
  }
  validate(a.opts);
  check_writable(a.out);  // before the work, so a bad path costs nothing
  const study s = run_sweep(a.opts);
  write_study(s, a.out);
  if (!a.quiet) {
    fmt::print("{:<22} {:<20} {:>8} {:>9}  {}\n", "problem", "integrator", "expected", "observed", "fit levels");
    for (const auto& ps : s.problems)
      for (const auto& is : ps.integrators) {
        const std::string observed = is.fit.state == fit_result::status::fitted ? fmt::format("{:.3f}", is.fit.order)
                                     : is.fit.state == fit_result::status::exact ? "exact"
                                                                                 : "n/a";
        fmt::print("{:<22} {:<20} {:>8} {:>9}  {}\n", ps.problem->name(), is.info.name, is.info.order, observed,
                   fmt::join(is.fit.levels, ","));
      }
    for (const auto& ps : s.problems)
      for (const auto& r : ps.truth.references)
        fmt::print("reference {:<12} on {:<22} vs {:<12} pos {:.2e} vel {:.2e}  ({} steps, {} f evals)\n",
                   r.solution.source, ps.problem->name(), r.compared_with, r.vs.pos_rel, r.vs.vel_rel,
                   r.solution.stats.steps, r.solution.stats.rhs_evals_counted);
  }
  fmt::print("wrote {} ({} problems, {} levels) in {:.2f} s\n", a.out, s.problems.size(), a.opts.levels, s.wall_seconds);
  return 0;
}

struct advise_args {
  std::string problem, tol_text, metric = "err_pos_max", study = "results/study.h5";
  bool json = false;
};

// Exit 0 with an answer, 3 when no method in the file meets the tolerance (the answer
// then names the best error achieved and by whom); bad input and unreadable files throw.
int cmd_advise(const advise_args& a) {
  const double tol = parse_number(a.tol_text, "--tol");
  if (!(tol > 0.0)) throw usage_error(fmt::format("--tol must be > 0, got {}", a.tol_text));
  const advise_result r = advise(read_advise_input(a.study, a.problem, a.metric), tol);
  if (!a.json) {
    fmt::print("{}", format_advice(r));
    return r.ranked.empty() ? advise_exit_no_method : 0;
  }
  auto pick = [](const advise_pick& p) {
    return json{{"method", p.method},
                {"kind", p.peer ? "peer" : "integrator"},
                {"param_name", p.adaptive ? "rtol" : "dt"},
                {"param", p.row.param},
                {"force_evals", p.row.force_evals},
                {"time_ns", p.row.time_ns},  // NaN (not timed) is written as null by nlohmann::json
                {"error", p.row.error},
                {"cost", p.cost},
                {"diverged_rows", p.diverged_rows},
                {"smallest_diverged", p.smallest_diverged ? json(*p.smallest_diverged) : json(nullptr)},
                {"largest_diverged", p.largest_diverged ? json(*p.largest_diverged) : json(nullptr)}};
  };
  json out = {{"problem", r.problem}, {"metric", r.metric}, {"tol", r.tol},     {"unit", r.unit},
              {"cost", r.cost},       {"timings", r.timings}, {"met", !r.ranked.empty()}};
  out["choice"] = r.ranked.empty() ? json(nullptr) : pick(r.ranked.front());
  out["runners_up"] = json::array();
  for (std::size_t i = 1; i < r.ranked.size(); ++i) out["runners_up"].push_back(pick(r.ranked[i]));
  out["excluded"] = json::array();
  for (const auto& e : r.excluded) out["excluded"].push_back({{"method", e.method}, {"reason", e.reason}});
  out["best_achieved"] = r.best_achieved ? pick(*r.best_achieved) : json(nullptr);
  std::cout << out.dump(2) << "\n";
  return r.ranked.empty() ? advise_exit_no_method : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"stepbench: accuracy, stability and speed of time integrators on game-physics problems"};
  app.require_subcommand(1);

  bool list_json = false;
  auto* list = app.add_subcommand("list", "list problems (with parameters) and integrators (with orders)");
  list->add_flag("--json", list_json, "print JSON");

  run_args ra;
  auto* run = app.add_subcommand("run", "integrate one problem with one integrator and print the errors");
  run->add_option("--problem", ra.problem, "problem name (see list)")->required();
  run->add_option("--integrator", ra.integrator, "integrator name (see list)")->required();
  run->add_option("--dt", ra.dt_text, "timestep [s]")->required();
  run->add_option("--horizon", ra.horizon_text, "end time [s] (default: the problem's)");
  run->add_option("--set", ra.sets, "override a parameter, name=value (repeatable)");
  run->add_flag("--json", ra.json, "print JSON");

  sweep_args sa;
  auto* sweep = app.add_subcommand("sweep", "convergence sweep of every (problem, integrator) into an HDF5 study file");
  sweep->add_option("--problem", sa.opts.problems, "restrict to these problems (repeatable)");
  sweep->add_option("--integrator", sa.opts.integrators, "restrict to these integrators (repeatable)");
  sweep->add_option("--levels", sa.opts.levels, "timesteps in the halving ladder")->capture_default_str();
  sweep->add_option("--base-steps", sa.opts.base_steps, "steps at the coarsest level")->capture_default_str();
  sweep->add_option("--set", sa.sets, "override a parameter, problem.name=value (repeatable)");
  sweep->add_option("--out", sa.out, "study file to write")->capture_default_str();
  sweep->add_flag("--quiet", sa.quiet, "print only the summary line");

  advise_args aa;
  auto* advise_cmd = app.add_subcommand(
      "advise", "the cheapest stable method and its dt (or tolerance) for an error, from a study file");
  advise_cmd->add_option("--problem", aa.problem, "problem name (one in the study file)")->required();
  advise_cmd->add_option("--tol", aa.tol_text, "largest acceptable error, in the problem's units (> 0)")->required();
  advise_cmd->add_option("--metric", aa.metric, "err_pos_max, err_pos_final, err_pos_rms or err_vel_final")
      ->capture_default_str();
  advise_cmd->add_option("--study", aa.study, "study file to read")->capture_default_str();
  advise_cmd->add_flag("--json", aa.json, "print JSON");
  advise_cmd->footer("exit codes: 0 answer, 1 study file unreadable, 2 bad usage, 3 no method meets the tolerance\n");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 2;
  }
  try {
    if (*list) return cmd_list(list_json);
    if (*run) return cmd_run(ra);
    if (*sweep) return cmd_sweep(sa);
    if (*advise_cmd) return cmd_advise(aa);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stepbench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

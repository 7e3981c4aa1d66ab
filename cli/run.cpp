// `stepbench run`: one problem, one method, one dt (or tolerance); prints the final state,
// the true state, the errors and the work.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/drive.hpp"
#include "core/measure.hpp"
#include "registry/registry.hpp"
#include "run/sweep.hpp"

namespace stepbench {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(work_counters, force_evals, jacobian_evals, newton_iterations, linear_solves)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(run_metrics, err_pos_final, err_vel_final, err_pos_max, err_pos_rms, energy_drift,
                                   diverged, failed)  // NaN is written as null
}  // namespace stepbench

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct run_args {
  std::string problem, method, dt_text, tol_text, horizon_text, reference_budget_text;
  std::vector<std::string> sets;
  bool json = false;
};

// One entry of a printed state: 12 significant digits, and never "-0".
std::string entry(double x, int digits = 12) { return fmt::format("{:.{}g}", x == 0.0 ? 0.0 : x, digits); }

// The Euclidean norm of a state, as printed (6 digits).
std::string norm(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return entry(std::sqrt(sum), 6);
}

// A state vector, printed once and compactly: every entry up to six, else the first and
// last three (6 digits) with the count and the Euclidean norm.
std::string compact(const std::vector<double>& v) {
  constexpr std::size_t whole = 6, ends = 3;
  std::string out = "[";
  if (v.size() <= whole) {
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + entry(v[i]);
    return out + "]";
  }
  for (std::size_t i = 0; i < ends; ++i) out += entry(v[i], 6) + ", ";
  out += "...";
  for (std::size_t i = v.size() - ends; i < v.size(); ++i) out += ", " + entry(v[i], 6);
  return out + fmt::format("] ({} entries, norm {})", v.size(), norm(v));
}

// The computed vector and the true one: both in full when short; when long, the computed
// one and the true one's norm (their difference is the error below).
std::string with_truth(const std::vector<double>& y, const std::vector<double>& truth, const std::string& source) {
  if (y.size() <= 6) return fmt::format("{}   (true {}{})", compact(y), compact(truth), source);
  return fmt::format("{}   (true: norm {}{})", compact(y), norm(truth), source);
}

int run_run(const run_args& a) {
  // What `run` was asked, checked: the problem with its --set overrides, the method, its
  // dt or tolerance, and the horizon. Throws std::invalid_argument naming the problem.
  make_problem(a.problem);  // an unknown problem is named before an unknown method
  const method_info& m = find_method(a.method);
  sweep_options so;
  for (const auto& s : a.sets) add_override(so.overrides, s, std::vector{a.problem});
  const auto instance = configured_problem(a.problem, so);
  const problem_instance& problem = *instance;
  const bool fixed = m.kind == method_kind::fixed_step;
  const char *kind = fixed ? "is a fixed-step method" : "is adaptive", *given = fixed ? "--dt" : "--tol";
  if ((fixed ? a.dt_text : a.tol_text).empty())
    throw std::invalid_argument(fmt::format("{} {}: give {}", m.name, kind, given));
  if (!(fixed ? a.tol_text : a.dt_text).empty())
    throw std::invalid_argument(fmt::format("{} {}: {} does not apply", m.name, kind, fixed ? "--tol" : "--dt"));
  const double param = parse_positive(fixed ? a.dt_text : a.tol_text, given);
  if (!fixed && !(param < 1.0)) throw std::invalid_argument(fmt::format("--tol must be < 1, got {}", a.tol_text));
  const double horizon = a.horizon_text.empty() ? problem.horizon() : parse_positive(a.horizon_text, "--horizon");
  if (fixed && param > horizon)
    throw std::invalid_argument(
        fmt::format("--dt {} s is longer than the horizon of {} ({:g} s): give a smaller --dt or a longer --horizon",
                    a.dt_text, a.problem, horizon));
  if (fixed && horizon / param > 1e9)
    throw std::invalid_argument(fmt::format("--dt {} needs more than 1e9 steps to reach {}", param, horizon));

  // Fixed steps are measured at the grid times nearest j T / 32, so the run itself is
  // the one a user would make; adaptive runs at j T / 32 exactly.
  constexpr int sample_count = 32;
  const auto times = fixed ? nearest_grid_times(horizon, param, sample_count) : sample_times(horizon, sample_count);
  const run_result run = problem.run(m.name, param, horizon, times);
  truth_options topts;
  topts.run_references = !problem.has_closed_form();
  if (!a.reference_budget_text.empty()) {
    topts.reference_budget = parse_positive(a.reference_budget_text, "--reference-budget");
  }
  const truth_table truth = build_truth(problem, times, topts);
  const run_metrics metrics = measure(problem, run, truth);

  // Positions and velocities as the errors are measured: the problem's observed
  // positions (n_pendulum's bobs in m, not its link angles), else its state; for the run,
  // the ones it draws (xpbd's particles: run_record's drawn_final).
  const int dim = problem.observed_dim();
  auto part = [&](const std::vector<double>& y, int offset) {
    if (y.empty()) return std::vector<double>{};
    const std::vector<double> o = problem.observed(y);
    return std::vector<double>(o.begin() + offset, o.begin() + offset + dim);
  };
  auto drawn = [&](int offset) {
    if (run.drawn_final.empty()) return part(run.final_y, offset);
    return std::vector<double>(run.drawn_final.begin() + offset, run.drawn_final.begin() + offset + dim);
  };
  json out = run.work;  // force_evals, jacobian_evals, newton_iterations, linear_solves
  out.update(metrics);  // the errors, diverged and failed
  out.update({{"problem", a.problem},
              {"integrator", m.name},
              {"origin", to_string(m.origin)},
              {"kind", to_string(m.kind)},
              {fixed ? "dt" : "tol", param},
              {"horizon", horizon},
              {"steps", run.steps},
              {"rejected_steps", run.rejected_steps},
              {"position", drawn(0)},
              {"velocity", drawn(dim)},
              {"truth_source", truth.source},
              {"true_position", part(truth.y.back(), 0)},
              {"true_velocity", part(truth.y.back(), dim)}});
  if (!metrics.note.empty()) out["note"] = metrics.note;
  if (a.json) {
    std::cout << out.dump(2) << "\n";
    return metrics.failed ? 1 : 0;
  }
  const std::string unit(problem.position_unit());
  fmt::print("{} with {}: {} to t = {:g} s, {}{}, {}\n", a.problem, m.name,
             fixed ? fmt::format("dt {:g} s", param) : fmt::format("tol {:g}", param), horizon,
             count_of(run.steps, "step"), fixed ? "" : fmt::format(" ({} rejected)", run.rejected_steps),
             count_of(run.work.force_evals, "force evaluation"));
  if (run.work.jacobian_evals || run.work.newton_iterations)
    fmt::print("  {}, {}, {}\n", count_of(run.work.jacobian_evals, "Jacobian evaluation"),
               count_of(run.work.newton_iterations, "Newton iteration"),
               count_of(run.work.linear_solves, "linear solve"));
  const std::string pos_label = fmt::format("position [{}]", unit), vel_label = fmt::format("velocity [{}/s]", unit);
  const std::size_t w = std::max<std::size_t>(14, vel_label.size());
  fmt::print("  {:<{}} {}\n", pos_label, w,
             with_truth(drawn(0), part(truth.y.back(), 0), fmt::format(", from {}", truth.source)));
  fmt::print("  {:<{}} {}\n", vel_label, w, with_truth(drawn(dim), part(truth.y.back(), dim), ""));
  fmt::print("  {:<{}} {:.6e} {}\n", "err_pos_final", w, metrics.err_pos_final, unit);
  fmt::print("  {:<{}} {:.6e} {}/s\n", "err_vel_final", w, metrics.err_vel_final, unit);
  fmt::print("  {:<{}} {:.6e} {}\n", "err_pos_max", w, metrics.err_pos_max, unit);
  fmt::print("  {:<{}} {:.6e} {}\n", "err_pos_rms", w, metrics.err_pos_rms, unit);
  if (problem.has_energy())
    fmt::print("  {:<{}} {:+.6e} (relative, at the horizon)\n", "energy_drift", w, metrics.energy_drift);
  if (metrics.diverged) fmt::print("  DIVERGED: {}\n", metrics.note);
  if (metrics.failed) fmt::print("  FAILED: {}\n", metrics.note);
  return metrics.failed ? 1 : 0;
}

}  // namespace

command add_run(CLI::App& app) {
  auto a = std::make_shared<run_args>();
  auto* sub = app.add_subcommand("run", "integrate one problem with one method and print the errors");
  sub->add_option("--problem", a->problem, "problem name (see list)")->required();
  sub->add_option("--integrator,--method", a->method, "method name (see list): ours or a peer")->required();
  sub->add_option("--dt", a->dt_text, "timestep [s] (fixed-step methods)");
  sub->add_option("--tol", a->tol_text, "relative tolerance (adaptive methods)");
  sub->add_option("--horizon", a->horizon_text, "end time [s] (default: the problem's)");
  sub->add_option("--set", a->sets, "override a parameter, problem.name=value or name=value (repeatable)");
  sub->add_option("--reference-budget", a->reference_budget_text,
                  "run the references only when their predicted work (coordinates x w_max T) is at most this "
                  "(default: always); above it the run is judged on stability alone");
  sub->add_flag("--json", a->json, "print JSON");
  return {sub, [a] { return run_run(*a); }};
}

}  // namespace stepbench::cli

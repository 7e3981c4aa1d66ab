// `stepbench advise`: the cheapest method and its dt (or tolerance) for an error, from a
// study file (judge/advise.hpp).
#include "judge/advise.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "judge/scan.hpp"
#include "judge/verdict.hpp"
#include "parts/study.hpp"
#include "registry/registry.hpp"
#include "render/advise.hpp"
#include "render/scan.hpp"
#include "run/scan.hpp"
#include "run/sweep.hpp"
#include "store/scan.hpp"
#include "study/scan.hpp"

namespace stepbench {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(wp_pick, param, interpolated, force_evals, time_ns, error, cost, cost_lo, cost_hi,
                                   diverged_rows)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(frame_option, method, substeps, completed, diverged, err_pos_max, cost_per_frame,
                                   note)
}  // namespace stepbench

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct advise_args {
  std::string problem, tol_text, metric = "err_pos_max", study = "results/study.h5";
  std::string hz_text;            // set: the frame-rate question instead
  std::string scan, scan_name;    // set: the range question, from a scan (study/scan.hpp)
  std::vector<std::string> sets;  // P.name=value: a scene the study did not run, run here
  bool json = false;
  bool time = false;  // --hz: rank the runs made here by times measured here
};

json pick_json(const advice& a, const wp_pick& p) {
  const auto& m = a.methods[p.method];
  json out = p;  // NaN (time_ns when not timed) is written as null
  out.update({{"method", m.name},
              {"origin", to_string(m.origin)},
              {"param_name", param_name(m.kind)},
              {"smallest_diverged", p.smallest_diverged ? json(*p.smallest_diverged) : json(nullptr)},
              {"largest_diverged", p.largest_diverged ? json(*p.largest_diverged) : json(nullptr)}});
  return out;
}

json frame_advice_json(const frame_advice& f) {
  json out = {{"problem", f.problem}, {"scene", f.scene},         {"hz", f.hz},           {"tol", f.tol},
              {"unit", f.unit},       {"cost_kind", f.cost_kind}, {"horizon", f.horizon}, {"met", f.met()}};
  out["choice"] = f.met() ? json(f.ranked.front()) : json(nullptr);
  out["ranked"] = f.ranked;
  out["one_step"] = f.one_step;
  out["not_meeting"] = f.not_meeting;
  return out;
}

json advice_json(const advice& a) {
  const auto answer = a.result.answer(a.methods);
  json out = {{"problem", a.problem}, {"scene", a.scene},      {"metric", a.metric}, {"tol", a.tol},
              {"unit", a.unit},       {"cost", a.result.cost}, {"timings", a.timed}, {"met", a.met()}};
  out["choice"] = answer ? pick_json(a, *answer) : json(nullptr);
  out["runners_up"] = json::array();
  for (const auto& p : a.result.ranked)
    if (!answer || p.method != answer->method) out["runners_up"].push_back(pick_json(a, p));
  out["excluded"] = json::array();
  for (const auto& e : a.result.excluded)
    out["excluded"].push_back({{"method", a.methods[e.method].name}, {"reason", e.reason}});
  out["best_achieved"] = a.result.best_achieved ? pick_json(a, *a.result.best_achieved) : json(nullptr);
  return out;
}

// The study file at `path`; a file `stepbench scan` wrote (scans, no problems) is refused
// with the option that reads it.
study study_not_scan(const std::string& path) {
  study s = read_study(path);
  if (!s.problems.empty()) return s;
  const std::vector<scan_result> scans = read_scans(path);
  if (!scans.empty())
    throw std::invalid_argument(
        fmt::format("'{}' holds a scan of {}, not a study: read it with `stepbench advise --scan {} --tol X`", path,
                    scans.front().options.problem, path));
  return s;
}

// The frame-rate question for a scene or rate the study lacks: its frame-rate runs at that
// rate, run here as a scan of one point (study/scan.hpp), answered by the scan's rule.
// Ranked as a scan ranks: by the study's measured ns per force evaluation when it is timed.
int advise_frame_here(const advise_args& args, const std::map<std::string, double>& fixed, double hz, double tol,
                      const std::string& why, const study* costs) {
  scan_options o;
  o.problem = args.problem;
  o.hz = {hz};
  o.tol = tol;
  o.fixed = fixed;
  validate(o);
  if (args.time) {
    const auto start = std::chrono::steady_clock::now();
    o.ns_per_force_eval = eval_costs_timed_here(o);
    o.cost_source = cost_timed_here;
    fmt::print(stderr, "{}: timed each method's force evaluation on this scene here ({:.1f} s)\n", why,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  } else if (costs) {
    take_costs(o, *costs, args.study);
  }
  fmt::print(stderr, "{}: running {}'s frame-rate runs at {:g} Hz here ({}ranked by {})\n", why, args.problem, hz,
             args.time ? "" : "untimed; ",
             args.time               ? "the time a force evaluation measured here"
             : o.cost_source.empty() ? "force evaluations"
                                     : "the study's measured time a force evaluation");
  const scan_answer a = answer_scan(run_scan(o), tol);
  print_answer(args.json, scan_answer_json(a), format_scan_answer(a));
  return a.choices.front().method.empty() ? advise_exit_no_method : 0;
}

// The dt (or tolerance) question for a scene the study did not run: its sweep, run here.
study sweep_here(const std::string& problem, const parameter_overrides& sets) {
  sweep_options o;
  o.problems = {problem};
  o.overrides = sets;
  o.parts = {"sweep"};
  validate(o);
  fmt::print(stderr, "--set makes a scene the study did not run: sweeping {} here (untimed)\n", problem);
  return run_sweep(o);
}

int run_advise(const advise_args& args) {
  const double tol = parse_positive(args.tol_text, "--tol");
  if (!args.scan.empty()) {
    if (!args.hz_text.empty()) throw std::invalid_argument("--scan answers at the scan's frame rates; drop --hz");
    if (!args.sets.empty()) throw std::invalid_argument("--scan answers for the scan's scenes; drop --set");
    if (args.time) throw std::invalid_argument("--scan answers from the scan's runs; drop --time");
    const scan_result s = read_scan(args.scan, args.scan_name);
    if (!args.problem.empty() && args.problem != s.options.problem)
      throw std::invalid_argument(
          fmt::format("the scan in '{}' is of {}, not {}", args.scan, s.options.problem, args.problem));
    const scan_answer a = answer_scan(s, tol);
    print_answer(args.json, scan_answer_json(a), format_scan_answer(a));
    for (const auto& c : a.choices)
      if (!c.method.empty()) return 0;
    return advise_exit_no_method;
  }
  if (args.problem.empty()) throw std::invalid_argument("--problem is required (or --scan FILE)");
  if (args.time && args.hz_text.empty())
    throw std::invalid_argument(
        "--time times the frame-rate runs of --hz; give --hz (the study's timings answer the rest)");
  parameter_overrides sets;
  for (const auto& text : args.sets) add_override(sets, text, std::vector<std::string>{args.problem});
  const auto fixed = sets.count(args.problem) ? sets.at(args.problem) : std::map<std::string, double>{};
  if (!args.hz_text.empty()) {
    const double hz = parse_positive(args.hz_text, "--hz");
    if (args.metric != "err_pos_max")
      throw std::invalid_argument("--hz answers for err_pos_max only (the frame-rate study measures that)");
    // A scene or rate the study lacks is run here, ranked by the study's costs if it has them.
    std::optional<study> s;
    if (std::filesystem::exists(args.study)) s = study_not_scan(args.study);
    const std::string missing = args.time        ? "--time"
                                : !s             ? fmt::format("there is no study file '{}'", args.study)
                                : !fixed.empty() ? "--set makes a scene the study did not run"
                                                 : frame_runs_missing(*s, args.problem, hz);
    if (!missing.empty()) return advise_frame_here(args, fixed, hz, tol, missing, s ? &*s : nullptr);
    const frame_advice f = advise_frame(*s, args.problem, hz, tol);
    print_answer(args.json, frame_advice_json(f), format_frame_advice(f));
    return f.met() ? 0 : advise_exit_no_method;
  }
  const study s = fixed.empty() ? study_not_scan(args.study) : sweep_here(args.problem, sets);
  const advice a = advise(s, args.problem, args.metric, tol);
  print_answer(args.json, advice_json(a), format_advice(a));
  return a.met() ? 0 : advise_exit_no_method;
}

}  // namespace

command add_advise(CLI::App& app) {
  auto a = std::make_shared<advise_args>();
  auto* sub = app.add_subcommand(
      "advise", "the cheapest stable method and its dt (or tolerance) for an error, from a study file");
  sub->add_option("--problem", a->problem, "problem name (one in the study file; required unless --scan)");
  sub->add_option("--tol", a->tol_text, "largest acceptable error, in the problem's units (> 0)")->required();
  sub->add_option("--metric", a->metric, "err_pos_max, err_pos_final, err_pos_rms or err_vel_final")
      ->capture_default_str();
  sub->add_option("--hz", a->hz_text,
                  "frame rate: the methods stable at one step a frame, and the cheapest method and substeps a frame "
                  "that meet --tol (from the study's frame-rate runs; any other rate is run here)");
  sub->add_option("--set", a->sets,
                  "P.name=value (repeatable): a scene the study did not run; its runs are made here, untimed");
  sub->add_option("--study", a->study, "study file to read")->capture_default_str();
  sub->add_option("--scan", a->scan,
                  "a file written by `stepbench scan`: the cheapest method and substeps that hold over the whole "
                  "range at each rate, and where each method breaks at one step a frame");
  sub->add_option("--name", a->scan_name, "the scan in that file (when it holds more than one)");
  sub->add_flag("--time", a->time,
                "with --hz: run the frame-rate runs here and rank them by each method's time a force evaluation "
                "measured here on this scene (about a second more), not by the study's");
  sub->add_flag("--json", a->json, "print JSON");
  sub->footer("exit codes: 0 answer, 1 study file unreadable, 2 bad usage, 3 no method meets the tolerance\n");
  return {sub, [a] { return run_advise(*a); }};
}

}  // namespace stepbench::cli

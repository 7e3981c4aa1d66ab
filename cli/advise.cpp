// `stepbench advise`: the cheapest method and its dt (or tolerance) for an error, from a
// study file (judge/advise.hpp).
#include "judge/advise.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "judge/scan.hpp"
#include "judge/verdict.hpp"
#include "parts/study.hpp"
#include "render/advise.hpp"
#include "render/scan.hpp"
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
  std::string hz_text;          // set: the frame-rate question instead
  std::string scan, scan_name;  // set: the range question, from a scan (study/scan.hpp)
  bool json = false;
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
  json out = {{"problem", f.problem},     {"hz", f.hz},           {"tol", f.tol},  {"unit", f.unit},
              {"cost_kind", f.cost_kind}, {"horizon", f.horizon}, {"met", f.met()}};
  out["choice"] = f.met() ? json(f.ranked.front()) : json(nullptr);
  out["ranked"] = f.ranked;
  out["one_step"] = f.one_step;
  out["not_meeting"] = f.not_meeting;
  return out;
}

json advice_json(const advice& a) {
  const auto answer = a.result.answer(a.methods);
  json out = {{"problem", a.problem},  {"metric", a.metric}, {"tol", a.tol},  {"unit", a.unit},
              {"cost", a.result.cost}, {"timings", a.timed}, {"met", a.met()}};
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

int run_advise(const advise_args& args) {
  const double tol = parse_positive(args.tol_text, "--tol");
  if (!args.scan.empty()) {
    if (!args.hz_text.empty()) throw std::invalid_argument("--scan answers at the scan's frame rates; drop --hz");
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
  if (!args.hz_text.empty()) {
    const double hz = parse_number(args.hz_text, "--hz");
    if (args.metric != "err_pos_max")
      throw std::invalid_argument("--hz answers for err_pos_max only (the frame-rate study measures that)");
    const frame_advice f = advise_frame(study_not_scan(args.study), args.problem, hz, tol);
    print_answer(args.json, frame_advice_json(f), format_frame_advice(f));
    return f.met() ? 0 : advise_exit_no_method;
  }
  const study s = study_not_scan(args.study);
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
                  "that meet --tol (from the study's frame-rate runs: 30, 60, 120 or 240)");
  sub->add_option("--study", a->study, "study file to read")->capture_default_str();
  sub->add_option("--scan", a->scan,
                  "a file written by `stepbench scan`: the cheapest method and substeps that hold over the whole "
                  "range at each rate, and where each method breaks at one step a frame");
  sub->add_option("--name", a->scan_name, "the scan in that file (when it holds more than one)");
  sub->add_flag("--json", a->json, "print JSON");
  sub->footer("exit codes: 0 answer, 1 study file unreadable, 2 bad usage, 3 no method meets the tolerance\n");
  return {sub, [a] { return run_advise(*a); }};
}

}  // namespace stepbench::cli

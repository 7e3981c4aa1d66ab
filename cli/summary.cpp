// `stepbench summary [--study FILE] [--out FILE]`: the README's answer as data. A small JSON
// digest of a study file, committed beside the README (results/summary.json, written by
// scripts/study.sh after the main study): per problem, the game programmer's answer at 60 Hz
// for 1e-2, 1e-3 and 1e-4 in the problem's unit (method, substeps, cost a frame), how many of
// our methods stay stable at one step a frame, and the scene as the study ran it; and the
// equal-error verdict against the library peers at 1e-6 .. 1e-12 (the verdict, its cost
// kind, the ratio, the noise factor it was judged against, and the ratio's two factors: force
// evaluations at equal error and time an evaluation). Every value is the study's own verdict
// tables (study/verdict.hpp), which `advise --hz` and the report read too: scripts/report
// --readme renders the README's block from this file, and a test fails when the README
// differs from that render.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "cli/commands.hpp"
#include "judge/scan.hpp"
#include "parts/study.hpp"
#include "registry/registry.hpp"
#include "store/study_file.hpp"
#include "study/verdict.hpp"

namespace stepbench::cli {
namespace {

// Keys in the order written: the file is read by people too.
using ordered = nlohmann::ordered_json;

// The README's question: a frame at this rate, at these errors (the "60 Hz, 1 mm",
// a coarser and a finer one beside it).
constexpr double summary_hz = 60.0;
constexpr std::array summary_targets{1e-2, 1e-3, 1e-4};
// The numerical-methods reader's question: ours against the fastest library peer at equal
// error, at the tight targets where the high-order methods compete.
constexpr std::array peer_targets{1e-6, 1e-8, 1e-10, 1e-12};

struct summary_args {
  std::string study = "results/study.h5", out = "results/summary.json";
};

bool same_target(double a, double b) { return std::abs(a / b - 1.0) < 1e-9; }

ordered summarize(const study& s, const std::string& path) {
  const auto* v = s.results.find<verdict_tables>();
  if (!v) throw std::runtime_error(fmt::format("'{}' has no verdict tables (a study without its verdict part)", path));
  const auto meta = [&](const char* key) {
    const auto it = s.record->meta.find(key);
    return it == s.record->meta.end() ? std::string() : it->second;
  };
  ordered out = {{"study",
                  {{"path", path},
                   {"git_commit", meta("git_commit")},
                   {"cpu", meta("cpu")},
                   {"created_utc", meta("created_utc")},
                   {"timed", s.timed.has_value()},
                   {"cost_kind", v->cost_kind}}},
                 {"hz", summary_hz},
                 {"targets", summary_targets},
                 {"problems", ordered::array()},
                 {"peer_targets", ordered::array()},
                 {"against_peers", ordered::array()},
                 {"against_peers_left_out", ordered::array()}};
  // The tight targets the study's verdict holds.
  std::vector<double> tight;
  for (double target : peer_targets)
    if (std::any_of(v->equal_error.begin(), v->equal_error.end(),
                    [&](const equal_error_verdict& e) { return same_target(e.target, target); }))
      tight.push_back(target);
  out["peer_targets"] = tight;
  // In the registry's order (`stepbench list`), as the report's tables are; the file's
  // groups come back in name order.
  std::vector<const problem_study*> order;
  for (const auto& name : problem_names())
    if (const problem_study* ps = s.find(name)) order.push_back(ps);
  for (const auto& ps : s.problems)
    if (std::find(order.begin(), order.end(), &ps) == order.end()) order.push_back(&ps);
  for (const problem_study* ps_ptr : order) {
    const problem_study& ps = *ps_ptr;
    ordered p = {
        {"name", ps.name}, {"unit", ps.unit}, {"scene", scene_text(ps.name, ps.params)}, {"answers", ordered::array()}};
    for (double target : summary_targets)
      for (const auto& a : v->frame_answers)
        if (a.problem == ps.name && a.hz == summary_hz && same_target(a.target, target))
          p["answers"].push_back({{"target", target},
                                  {"method", a.method.empty() ? ordered(nullptr) : ordered(a.method)},
                                  {"substeps", a.substeps},
                                  {"err_pos_max", a.err_pos_max},
                                  {"cost_per_frame", a.cost_per_frame},
                                  {"frame_share", a.frame_share}});
    int stable = 0, methods = 0;
    for (const auto& f : v->frame_rate)
      if (f.problem == ps.name && f.hz == summary_hz) {
        ++methods;
        stable += f.stable ? 1 : 0;
      }
    p["stable_at_one_step"] = stable;
    p["methods_at_one_step"] = methods;
    out["problems"].push_back(std::move(p));
    // The equal-error verdict at the tight targets, every cell (a one-sided one carries its
    // verdict word: "ours only", "peers only", "not reached"), for a problem where both
    // sides reach one of them; the others are named as left out.
    const auto text_or_null = [](const std::string& t) { return t.empty() ? ordered(nullptr) : ordered(t); };
    ordered cells = ordered::array();
    bool faced = false;
    for (double target : tight)
      for (const auto& e : v->equal_error)
        if (e.problem == ps.name && same_target(e.target, target)) {
          faced = faced || (e.ours.found() && e.peer.found());
          cells.push_back({{"target", target},
                           {"verdict", e.verdict},
                           {"cost_kind", e.cost_kind},
                           {"ours", text_or_null(e.ours.method)},
                           {"peer", text_or_null(e.peer.method)},
                           {"ratio", e.ratio},
                           {"noise_factor", e.noise_factor},
                           {"evals_ratio", e.evals_ratio},
                           {"per_eval_ratio", e.per_eval_ratio}});
        }
    if (faced)
      out["against_peers"].push_back({{"name", ps.name}, {"unit", ps.unit}, {"cells", cells}});
    else
      out["against_peers_left_out"].push_back(ps.name);
  }
  return out;
}

int run_summary(const summary_args& a) {
  const study s = read_study(a.study);
  const std::string text = summarize(s, a.study).dump(1) + "\n";
  if (a.out == "-") {
    std::fputs(text.c_str(), stdout);
    return 0;
  }
  check_writable(a.out);
  // Beside the target, then renamed over it: a failed write leaves the old summary whole.
  const std::string tmp = a.out + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    if (!f.flush()) {
      std::filesystem::remove(tmp);
      throw std::runtime_error(fmt::format("cannot write '{}'", a.out));
    }
  }
  std::filesystem::rename(tmp, a.out);
  fmt::print(stderr, "wrote {} from {}\n", a.out, a.study);
  return 0;
}

}  // namespace

command add_summary(CLI::App& app) {
  auto a = std::make_shared<summary_args>();
  auto* sub = app.add_subcommand(
      "summary",
      "the README's answer as data: a small JSON digest of a study file (per problem, the "
      "cheapest method and substeps a frame at 60 Hz for 1e-2, 1e-3 and 1e-4; ours against the fastest "
      "peer at 1e-6 .. 1e-12)");
  sub->add_option("--study", a->study, "study file to read")->capture_default_str();
  sub->add_option("--out", a->out, "JSON file to write (-: stdout)")->capture_default_str();
  return {sub, [a] { return run_summary(*a); }};
}

}  // namespace stepbench::cli

// `stepbench compare BASE NEW`: did anything get worse between two study files?
// (judge/compare.hpp). Exit 0 nothing regressed, 1 a regression, 2 could not compare:
// this command maps every error, including an unreadable file, to 2 itself, so CI can
// tell a regression from a broken job.
#include "judge/compare.hpp"

#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/work_precision.hpp"
#include "judge/verdict.hpp"
#include "parts/study.hpp"
#include "render/compare_render.hpp"
#include "render/verdict.hpp"
#include "study/verdict.hpp"

namespace stepbench {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(verdict_agreement, both_decided, agree, decided_in_one, flips)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(timing_row, problem, method, param_name, param, ratio, threshold)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(timing_summary, method, problems, rows, min_ratio, max_ratio, slower, faster)
}  // namespace stepbench

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct compare_args {
  std::string base, next, error_factor = "2", order_drop = "0.1", format = "text";
  bool json = false, allow_removed = false, require_base = false, gate_timing = false;
};

json value_json(const compare_value& v) {
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  return std::get<double>(v);  // NaN and inf are written as null
}

json change_json(const change& c) {
  return {{"problem", c.problem},
          {"method", c.method.empty() ? json(nullptr) : json(c.method)},
          {"param_name", c.param_name.empty() ? json(nullptr) : json(c.param_name)},
          {"param", c.param_name.empty() ? json(nullptr) : json(c.param)},
          {"what", c.what},
          {"old", value_json(c.old_value)},
          {"new", value_json(c.new_value)},
          {"ratio", c.ratio},
          {"note", c.note}};
}

json presence_json(const std::vector<presence>& items) {
  json out = json::array();
  for (const auto& p : items)
    out.push_back({{"problem", p.problem},
                   {"method", p.method.empty() ? json(nullptr) : json(p.method)},
                   {"what", p.what},
                   {"detail", p.detail}});
  return out;
}

json side_json(const timing& s) {
  return {{"time_ns", s.time_ns},
          {"time_ns_min", s.time_ns_min},
          {"time_ns_max", s.time_ns_max},
          {"repetitions", s.repetitions},
          {"spread", spread(s)}};
}

json comparison_json(const comparison& c) {
  const auto& o = c.options;
  json out = {{"base", {{"path", c.base_path}, {"timed", c.base_timed}, {"meta", c.base_meta}}},
              {"new", {{"path", c.new_path}, {"timed", c.new_timed}, {"meta", c.new_meta}}},
              {"result", c.exit_status() == 0 ? "ok" : "regression"},
              {"exit_status", c.exit_status()},
              {"summary_line", summary_line(c)}};
  out["summary"] = {{"regressions", c.count(change_kind::regression)},
                    {"improvements", c.count(change_kind::improvement)},
                    {"added", c.added.size()},
                    {"removed", c.removed.size()},
                    {"removed_gates", o.require_base},
                    {"timing_compared", c.timing_compared},
                    {"timing_rows", c.timing.size()},
                    {"timing_slower", c.slower()},
                    {"timing_faster", c.faster()},
                    {"timing_gates", o.gate_timing},
                    {"gating", c.gating()}};
  out["thresholds"] = {{"error_factor", o.error_factor},
                       {"error_floor_rel", error_floor_rel},
                       {"agreement_floor", agreement_floor},
                       {"order_drop", o.order_drop},
                       {"timing_noise_floor", timing_noise_floor},
                       {"timing_single_run_floor", timing_single_run_floor},
                       {"timing_spread_multiple", timing_spread_multiple},
                       {"require_base", o.require_base},
                       {"gate_timing", o.gate_timing},
                       {"description", describe_thresholds(o)}};
  out["differences"] = json::array();
  for (const auto& d : c.differences)
    out["differences"].push_back({{"what", d.what}, {"old", d.old_value}, {"new", d.new_value}});
  out["regressions"] = json::array();
  out["improvements"] = json::array();
  for (const auto& x : c.changes)
    out[x.kind == change_kind::regression ? "regressions" : "improvements"].push_back(change_json(x));
  out["added"] = presence_json(c.added);
  out["removed"] = presence_json(c.removed);
  json timing = {
      {"compared", c.timing_compared}, {"note", c.timing_note}, {"rows", json::array()}, {"methods", json::array()}};
  for (const auto& r : c.timing) {
    json row = r;
    row.update({{"old", side_json(r.old_time)},
                {"new", side_json(r.new_time)},
                {"flag", r.flag > 0   ? "slower"
                         : r.flag < 0 ? "faster"
                                      : ""}});
    timing["rows"].push_back(std::move(row));
  }
  for (const auto& s : c.timing_summaries) {
    json summary = s;
    summary["geomean_ratio"] = s.geomean;
    timing["methods"].push_back(std::move(summary));
  }
  out["timing"] = std::move(timing);
  return out;
}

int run_compare(const compare_args& a) {
  try {
    compare_options opts;
    opts.error_factor = parse_number(a.error_factor, "--error-factor");
    opts.order_drop = parse_number(a.order_drop, "--order-drop");
    if (a.allow_removed && a.require_base)
      throw std::invalid_argument("--allow-removed and --require-base: choose one");
    opts.require_base = a.require_base;
    opts.gate_timing = a.gate_timing;
    if (a.json && a.format == "md") throw std::invalid_argument("--json and --format md: choose one");
    const std::string format = a.json ? "json" : a.format;
    const std::vector<study> files = read_studies({a.base, a.next});  // read at once
    const study &base = files[0], &next = files[1];
    const comparison c = compare_studies(base, next, opts);
    // The equal-error verdicts of two timed studies side by side (informs, never gates).
    std::optional<verdict_agreement> verdicts;
    const auto* base_verdict = base.results.find<verdict_tables>();
    const auto* next_verdict = next.results.find<verdict_tables>();
    if (c.base_timed && c.new_timed && base_verdict && next_verdict)
      verdicts = compare_verdicts(*base_verdict, *next_verdict);
    if (format == "json") {
      json out = comparison_json(c);
      if (verdicts) out["verdicts"] = *verdicts;
      std::cout << out.dump(2) << "\n";
    } else {
      std::cout << (format == "md" ? format_markdown(c) : format_text(c));
      if (verdicts) std::cout << "\n" << format_verdict_agreement(*verdicts);
    }
    std::cout.flush();
    // The verdict on stderr too, where a CI log shows it whatever the output went to.
    if (format != "text") fmt::print(stderr, "stepbench compare: {} (exit {})\n", summary_line(c), c.exit_status());
    return c.exit_status();
  } catch (const std::exception& e) {
    fmt::print(stderr, "stepbench: error: {}\n", e.what());
    return compare_exit_cannot_compare;
  }
}

std::string help_footer() {
  std::string s = "Thresholds (the defaults):\n";
  for (const auto& line : describe_thresholds(compare_options{})) s += "  - " + line + "\n";
  s += "The output states the thresholds in force.\n"
       "exit codes: 0 nothing regressed; 1 a regression (with --gate-timing also a flagged slowdown); 2 could not "
       "compare: bad usage, a file missing, unreadable, truncated, corrupt, not a stepbench study or of a format "
       "this build does not read, or two files of different format versions\n";
  return s;
}

}  // namespace

command add_compare(CLI::App& app) {
  auto a = std::make_shared<compare_args>();
  auto* sub =
      app.add_subcommand("compare", "did anything get worse? Compare two study files: accuracy gates, timing informs");
  sub->add_option("base", a->base, "the study file to compare against (BASE)")->required()->type_name("BASE.h5");
  sub->add_option("new", a->next, "the study file to judge (NEW)")->required()->type_name("NEW.h5");
  sub->add_option("--error-factor", a->error_factor, "an error growing by more than this regresses (>= 1)")
      ->type_name("FACTOR")
      ->capture_default_str();
  sub->add_option("--order-drop", a->order_drop, "an observed order dropping by more than this regresses (>= 0)")
      ->type_name("DROP")
      ->capture_default_str();
  sub->add_flag("--require-base", a->require_base,
                "what only BASE has (a problem, a method, a reference, ladder rows) regresses: for a gate that "
                "compares a study with one of the same design");
  sub->add_flag("--allow-removed", a->allow_removed, "the default: what only BASE has is listed, not a regression");
  sub->add_flag("--gate-timing", a->gate_timing, "a flagged slowdown is a regression (exit 1)");
  sub->add_option("--format", a->format, "text, md (Markdown: a CI job summary, a pull-request comment) or json")
      ->check(CLI::IsMember({"text", "md", "json"}))
      ->capture_default_str();
  sub->add_flag("--json", a->json, "print one JSON document (as --format json)");
  sub->footer(help_footer());
  return {sub, [a] { return run_compare(*a); }};
}

}  // namespace stepbench::cli

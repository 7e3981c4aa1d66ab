// `stepbench ratios [--study FILE] [--json]`: the performance figures the README quotes,
// read from a timed study file (each figure from one run):
//   - step cost: our rk4 against the hand-written baseline, GSL's rk4 and Boost.Odeint's,
//     in ns per step at the finest dt where all of them were timed, on damped_spring; and
//     our rk8 against its hand-written baseline and the eighth-order library steps (GSL's
//     rk8pd, Odeint's runge_kutta_fehlberg78, ARKODE's default order-8 table) at fixed
//     dt, on damped_spring and pendulum;
//   - ns per right-hand-side call of the library solvers on the same problem (ARKODE and
//     CVODE against GSL: the price of a library's own code per call);
//   - equal error: on each problem, the time to reach each target error (err_pos_max)
//     for the cheapest of ours and the cheapest peer, by the study's one rule
//     (core/work_precision.hpp), their ratio, and the target (ours at most 0.5 x
//     the best peer; 1.0 or worse is open);
//   - the peers whose declared order does not hold.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "core/work_precision.hpp"
#include "judge/rows.hpp"
#include "parts/study.hpp"
#include "registry/registry.hpp"
#include "render/table_render.hpp"

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct ratios_args {
  std::string study = "results/study.h5";
  std::vector<std::string> problems{"damped_spring", "pendulum", "kepler"};
  std::vector<double> targets{1e-6, 1e-8, 1e-10, 1e-12};
  bool json = false;
};

// ns per step of each named method at the finest dt where all of them were timed.
json step_costs(const problem_study& p, const std::vector<std::string>& names) {
  std::vector<const method_study*> ms;
  for (const auto& n : names)
    if (const auto* m = p.find(n)) ms.push_back(m);
  if (ms.empty()) return nullptr;
  const auto& ladder = ms.front()->rows;
  for (std::size_t k = ladder.size(); k-- > 0;) {
    const double dt = ladder[k].param;
    json row = {
        {"problem", p.name}, {"dt", dt}, {"ns_per_step", json::object()}, {"force_evals_per_step", json::object()}};
    bool all = true;
    for (const auto* m : ms) {
      const auto it = std::find_if(m->rows.begin(), m->rows.end(), [&](const method_row& r) { return r.param == dt; });
      if (it == m->rows.end() || !std::isfinite(it->time.time_ns)) {
        all = false;
        break;
      }
      const double steps = static_cast<double>(it->steps);
      row["ns_per_step"][m->info.name] = it->time.time_ns / steps;
      row["force_evals_per_step"][m->info.name] = static_cast<double>(it->work.force_evals) / steps;
    }
    if (all) return row;
  }
  return nullptr;
}

// ns per right-hand-side call of the library solvers (every adaptive peer and the
// eighth-order fixed steps): the median over its timed rows of time / force evaluations
// (one figure per method, robust to the rows' spread).
json ns_per_call(const problem_study& p) {
  json out = json::object();
  for (const auto& m : p.methods) {
    const method_info& info = m.info;
    const bool solver = info.kind == method_kind::adaptive || info.declared_order >= 8.0;
    if (info.origin != method_origin::peer || !solver) continue;
    std::vector<double> v;
    for (const auto& r : m.rows)
      if (std::isfinite(r.time.time_ns) && r.work.force_evals > 0)
        v.push_back(r.time.time_ns / static_cast<double>(r.work.force_evals));
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    out[info.name] = {{"ns_per_call", v[v.size() / 2]}, {"rows", v.size()}, {"library", info.library}};
  }
  return out;
}

// The target for a ratio of ours over the best peer.
std::string verdict(double ours_over_peer) {
  if (!std::isfinite(ours_over_peer)) return "-";
  if (ours_over_peer <= 0.5) return "met";
  if (ours_over_peer < 1.0) return "ahead, short of 0.5";
  return "OPEN";
}

// Cheapest of ours and cheapest peer at a target, among the methods that were timed
// (wp_candidates::timed_methods: core/work_precision.hpp says why).
json equal_error(const problem_study& p, double target, const std::string& metric) {
  const std::vector<wp_method> methods = work_precision_input(p, metric);
  const auto r = cheapest(methods, target, true, metric, p.unit, wp_candidates::timed_methods);
  json out = {{"problem", p.name}, {"metric", metric}, {"target", target}, {"cost", r.cost}, {"ranked", json::array()}};
  const wp_pick *ours = nullptr, *peer = nullptr;
  for (const auto& pick : r.ranked) {
    const auto& m = methods[pick.method];
    out["ranked"].push_back({{"method", m.name},
                             {"origin", to_string(m.origin)},
                             {"param", pick.param},
                             {"interpolated", pick.interpolated},
                             {"time_ns", pick.time_ns},
                             {"time_ns_lo", pick.cost_lo},
                             {"time_ns_hi", pick.cost_hi},
                             {"error", pick.error}});
    if (m.origin == method_origin::ours && !ours) ours = &pick;
    if (m.origin == method_origin::peer && !peer) peer = &pick;
  }
  auto named = [&](const wp_pick* pick) {
    if (!pick) return json(nullptr);
    const auto& m = methods[pick->method];
    return json{{"method", m.name},           {"param_name", param_name(m.kind)},
                {"param", pick->param},       {"interpolated", pick->interpolated},
                {"time_ns", pick->cost},      {"time_ns_lo", pick->cost_lo},
                {"time_ns_hi", pick->cost_hi}};
  };
  out["ours"] = named(ours);
  out["peer"] = named(peer);
  // Ahead or behind only beyond the timing noise (core/work_precision.hpp).
  out["spread_verdict"] =
      ours && peer ? json(compare_at_equal_error(band_of(*ours), band_of(*peer), r.cost == "time_ns")) : json(nullptr);
  out["peer_over_ours"] = ours && peer && r.cost == "time_ns" ? json(peer->cost / ours->cost) : json(nullptr);
  out["ours_over_peer"] = ours && peer && r.cost == "time_ns" ? json(ours->cost / peer->cost) : json(nullptr);
  out["target_0_5"] = verdict(out["ours_over_peer"].is_null() ? NAN : out["ours_over_peer"].get<double>());
  return out;
}

// Every figure, as `--json` prints it and the text below is drawn from.
json ratios_json(const study& s, const ratios_args& a) {
  const auto& meta = s.record->meta;
  json out = {{"study", a.study}, {"cpu", meta.count("cpu") ? meta.at("cpu") : ""}};
  // null where the study has no damped_spring (print_ratios reads the key either way)
  const auto* spring = s.find("damped_spring");
  out["step_cost"] = spring ? step_costs(*spring, {"rk4", "baseline_rk4", "gsl_rk4", "odeint_rk4"}) : json(nullptr);
  // The example plugin RK4 (examples/plugins/rk4.c) against rk4, where a study ran it
  // (--plugin=build/plugins/librk4.so): the price of a step behind a C function pointer.
  out["step_cost_plugin"] = json::array();
  for (const char* name : {"pendulum", "spring_chain"})
    if (const auto* p = s.find(name); p && p->find("plugin_rk4"))
      if (auto sc = step_costs(*p, {"rk4", "plugin_rk4"}); !sc.is_null()) {
        if (p->params.count("masses")) sc["masses"] = p->params.at("masses");
        out["step_cost_plugin"].push_back(sc);
      }
  // A scene file's rk4 against the built-in rope's, per coordinate a step (a moving
  // mass's three in 3-D): what reading the forces as data costs (docs/scenes.md). Each
  // problem's finest timed dt; a step's cost does not depend on dt.
  out["step_cost_scene"] = json::array();
  const auto builtin = builtin_problem_names();
  if (const auto* chain = s.find("spring_chain"); chain && chain->find("rk4") && chain->dim > 0)
    for (const auto& p : s.problems)
      if (std::find(builtin.begin(), builtin.end(), p.name) == builtin.end() && p.find("rk4") && p.dim > 0) {
        const json mine = step_costs(p, {"rk4"}), theirs = step_costs(*chain, {"rk4"});
        if (mine.is_null() || theirs.is_null()) continue;
        const double a = mine["ns_per_step"]["rk4"].get<double>() / p.dim;
        const double b = theirs["ns_per_step"]["rk4"].get<double>() / chain->dim;
        out["step_cost_scene"].push_back({{"scene", p.name},
                                          {"scene_dim", p.dim},
                                          {"spring_chain_dim", chain->dim},
                                          {"scene_ns_per_coordinate_step", a},
                                          {"spring_chain_ns_per_coordinate_step", b},
                                          {"ratio", a / b}});
      }
  out["step_cost_rk8"] = json::array();
  out["ns_per_rhs_call"] = json::array();
  for (const auto& name : a.problems)
    if (const auto* p = s.find(name)) {
      // The eighth-order fixed steps at the finest dt where all were timed: ours, the
      // hand-written floor, and the libraries' (Odeint's only where Boost is present).
      std::vector<std::string> names{"rk8", "baseline_rk8", "gsl_rk8pd", "arkode_erk8"};
      if (p->find("odeint_rkf78")) names.push_back("odeint_rkf78");
      if (auto sc = step_costs(*p, names); !sc.is_null()) out["step_cost_rk8"].push_back(sc);
      out["ns_per_rhs_call"].push_back({{"problem", p->name}, {"methods", ns_per_call(*p)}});
    }
  out["equal_error"] = json::array();
  for (const auto& name : a.problems)
    if (const auto* p = s.find(name))
      for (double t : a.targets) out["equal_error"].push_back(equal_error(*p, t, "err_pos_max"));
  if (const auto* pend = s.find("pendulum")) out["equal_error_final"] = equal_error(*pend, 1e-6, "err_pos_final");
  out["order_notes"] = json::array();
  for (const auto& p : s.problems)
    for (const auto& m : p.methods)
      if (m.declared_order_holds == 0)
        out["order_notes"].push_back({{"problem", p.name},
                                      {"method", m.info.name},
                                      {"declared", m.info.declared_order},
                                      {"observed", m.fit.order}});
  return out;
}

// --- The text form: every table drawn by the one renderer (render/table_render.hpp). ---

std::string fixed(const json& v, int digits) {
  return v.is_null() ? "-" : fmt::format("{:.{}f}", v.get<double>(), digits);
}

// A step-cost record: each method's ns and force evaluations a step, then the ratios
// the README quotes, each with its target where it has one.
struct ratio_line {
  const char *x, *y;
  const char* target = nullptr;  // "<= 1.15"; nullptr: no target, the ratio informs
  bool (*met)(double) = nullptr;
};

void print_step_cost(const json& sc, const std::string& title, int ns_digits, const std::vector<ratio_line>& lines) {
  const auto& ns = sc["ns_per_step"];
  const auto& fe = sc["force_evals_per_step"];
  fmt::print("\n{}, {} at dt = {:.6g} s:\n", title, sc["problem"].get<std::string>(), sc["dt"].get<double>());
  table costs{{"method", right_column("time a step", "ns"), right_column("force evaluations a step")}, {}};
  for (const auto& [k, v] : ns.items()) costs.add({k, fixed(v, ns_digits), fixed(fe[k], 2)});
  fmt::print("{}", render_text(costs));
  table ratios{{"ratio", right_column("measured"), "target", "verdict"}, {}};
  for (const auto& l : lines) {
    if (!ns.contains(l.x) || !ns.contains(l.y)) continue;
    const double r = ns[l.x].get<double>() / ns[l.y].get<double>();
    ratios.add({fmt::format("{} / {}", l.x, l.y), fmt::format("{:.2f}", r), l.target ? l.target : "-",
                l.target ? (l.met(r) ? "met" : "NOT MET") : ""});
  }
  if (!ratios.empty()) fmt::print("\n{}", render_text(ratios));
}

void print_ns_per_call(const json& per_problem) {
  if (per_problem.empty()) return;
  fmt::print("\nns per right-hand-side call (median over the timed rows of time / force evaluations):\n");
  table t{{"method"}, {}};
  std::vector<std::string> methods;
  for (const auto& e : per_problem) {
    t.columns.push_back(right_column(e["problem"].get<std::string>(), "ns"));
    for (const auto& [k, v] : e["methods"].items())
      if (std::find(methods.begin(), methods.end(), k) == methods.end()) methods.push_back(k);
  }
  for (const auto& name : methods) {
    std::vector<std::string> row{name};
    for (const auto& e : per_problem)
      row.push_back(e["methods"].contains(name) ? fixed(e["methods"][name]["ns_per_call"], 1) : "-");
    t.add(std::move(row));
  }
  fmt::print("{}", render_text(t));
}

std::string who(const json& j) {
  if (j.is_null()) return "none reaches it";
  return fmt::format("{} {} at {} {:.3g}", j["method"].get<std::string>(), format_time_ns(j["time_ns"].get<double>()),
                     j["param_name"].get<std::string>() == "dt" ? "dt" : "tol", j["param"].get<double>());
}

void print_equal_error(const json& out) {
  fmt::print(
      "\nEqual error: time to reach err_pos_max, interpolated on each method's measured curve (log-log between the two "
      "rows that bracket the target; dt in s, tol relative; the study's rule)\n");
  table t{{"problem", right_column("target", "m or rad"), "fastest of ours", "fastest peer",
           right_column("peer / ours"), right_column("ours / peer"), "beyond the noise", "target <= 0.5"},
          {}};
  std::string open;
  for (const auto& e : out["equal_error"]) {
    t.add({e["problem"].get<std::string>(), fmt::format("{:.0e}", e["target"].get<double>()), who(e["ours"]),
           who(e["peer"]), fixed(e["peer_over_ours"], 2), fixed(e["ours_over_peer"], 2),
           e["spread_verdict"].is_null() ? "-" : e["spread_verdict"].get<std::string>(),
           e["target_0_5"].get<std::string>()});
    if (e["target_0_5"] == "OPEN")
      open += fmt::format("{}{} at {:.0e}", open.empty() ? "" : ", ", e["problem"].get<std::string>(),
                          e["target"].get<double>());
  }
  fmt::print("{}", render_text(t));
  fmt::print("  open (ours / peer >= 1.0): {}\n", open.empty() ? "none" : open);
  for (const auto& e : out["equal_error"]) {
    if (e["problem"] != "pendulum" || e["target"].get<double>() != 1e-6) continue;
    fmt::print("\n  pendulum, every method to err_pos_max = 1e-6:\n");
    table ranked{{"method", right_column("time"), "origin", right_column("at")}, {}};
    for (const auto& r : e["ranked"]) {
      const std::string origin = r["origin"].get<std::string>();
      ranked.add({r["method"].get<std::string>(), format_time_ns(r["time_ns"].get<double>()),
                  origin == "baseline" ? "baseline, for scale" : origin,
                  fmt::format("{:.3g}{}", r["param"].get<double>(), r["interpolated"].get<bool>() ? "" : " (row)")});
    }
    fmt::print("{}", render_text(ranked, "    "));
  }
  if (const auto& f = out["equal_error_final"]; !f.is_null())
    fmt::print("\n  pendulum to err_pos_final = 1e-6 instead: cheapest of ours {}, cheapest peer {}\n", who(f["ours"]),
               who(f["peer"]));
}

void print_ratios(const json& out, const std::string& study) {
  fmt::print("Performance ratios from {} ({}; each figure measured in that one run)\n", study,
             out["cpu"].get<std::string>());
  if (const auto& sc = out["step_cost"]; !sc.is_null()) {
    print_step_cost(sc, "Step cost", 2,
                    {{"rk4", "baseline_rk4", "<= 1.15", [](double r) { return r <= 1.15; }},
                     {"gsl_rk4", "rk4", ">= 6", [](double r) { return r >= 6.0; }},
                     {"rk4", "odeint_rk4", "<= 0.85", [](double r) { return r <= 0.85; }}});
    if (sc["force_evals_per_step"].contains("gsl_rk4"))
      fmt::print("  (GSL's rk4 estimates its error by step doubling: {:.2f} force evaluations a step against our 4)\n",
                 sc["force_evals_per_step"]["gsl_rk4"].get<double>());
  } else {
    fmt::print("\nStep cost: rk4 and its peers on damped_spring were not all timed\n");
  }
  for (const auto& sc : out["step_cost_plugin"]) {
    // The targets (34): at most 2x on the pendulum, whose force is one sine (the
    // call through the pointer and the copy of x are most of a step), and 1.3x on the
    // rope of 64 masses, where the force is most of it.
    const bool rope = sc["problem"] == "spring_chain";
    print_step_cost(sc,
                    rope ? fmt::format("Step cost, the example plugin RK4, {:g} masses", sc["masses"].get<double>())
                         : std::string("Step cost, the example plugin RK4"),
                    1,
                    {rope ? ratio_line{"plugin_rk4", "rk4", "<= 1.3 (64 masses)", [](double r) { return r <= 1.3; }}
                          : ratio_line{"plugin_rk4", "rk4", "<= 2", [](double r) { return r <= 2.0; }}});
    fmt::print(
        "  (the plugin's force is a call through a C function pointer that copies x{} into the problem's vectors: "
        "it cannot be inlined into the step as rk4's is)\n",
        rope ? " and v" : "");
  }
  for (const auto& sc : out["step_cost_scene"]) {
    // Issue 33's target: a scene file's rope of 64 masses within 1.3x of the built-in
    // spring_chain at 64 masses, per mass-step (here per coordinate: both are 3-D).
    const double r = sc["ratio"].get<double>();
    fmt::print(
        "\nStep cost of a scene file, rk4: {} ({} coordinates) {:.2f} ns a coordinate-step, spring_chain ({}) "
        "{:.2f}: ratio {:.2f} (target <= 1.3 for a rope of 64 masses against spring_chain at 64: {})\n",
        sc["scene"].get<std::string>(), sc["scene_dim"].get<int>(), sc["scene_ns_per_coordinate_step"].get<double>(),
        sc["spring_chain_dim"].get<int>(), sc["spring_chain_ns_per_coordinate_step"].get<double>(), r,
        r <= 1.3 ? "met" : "OPEN");
  }
  for (const auto& sc : out["step_cost_rk8"])
    print_step_cost(sc, "Step cost, eighth order", 1,
                    {{"rk8", "baseline_rk8", "<= 1.15", [](double r) { return r <= 1.15; }},
                     {"gsl_rk8pd", "rk8"},
                     {"odeint_rkf78", "rk8"},
                     {"arkode_erk8", "rk8"}});
  print_ns_per_call(out["ns_per_rhs_call"]);
  print_equal_error(out);
  for (const auto& n : out["order_notes"])
    fmt::print("  note: {} on {} declares order {:g} but achieves {:.2f}\n", n["method"].get<std::string>(),
               n["problem"].get<std::string>(), n["declared"].get<double>(), n["observed"].get<double>());
}

// The methods the step-cost ratios name: the performance contract scripts/perf-ratios.sh
// checks. Each must be in the registry, so a renamed method fails here, in one line,
// instead of dropping out of the figures unseen (Odeint's are there only where Boost is).
constexpr const char* step_cost_subjects[] = {"rk4",          "baseline_rk4", "gsl_rk4",    "rk8",
                                              "baseline_rk8", "gsl_rk8pd",    "arkode_erk8"};

int run_ratios(const ratios_args& a) {
  for (const auto& name : a.problems) make_problem(name);             // an unknown name: exit 2, naming the known ones
  for (const char* method : step_cost_subjects) find_method(method);  // unknown: exit 2, naming the known ones
  const study s = read_study(a.study);
  if (!s.timed) throw std::runtime_error(fmt::format("{} has no timings: run stepbench_bench --study_out", a.study));
  const json out = ratios_json(s, a);
  if (a.json)
    std::cout << out.dump(2) << "\n";
  else
    print_ratios(out, a.study);
  return 0;
}

}  // namespace

command add_ratios(CLI::App& app) {
  auto a = std::make_shared<ratios_args>();
  auto* sub = app.add_subcommand("ratios", "the performance ratios and equal-error table, from a timed study file");
  sub->add_option("--study", a->study, "timed study file (stepbench_bench --study_out)")->capture_default_str();
  sub->add_option("--problem", a->problems, "problems of the equal-error table")->capture_default_str();
  sub->add_flag("--json", a->json, "print JSON");
  return {sub, [a] { return run_ratios(*a); }};
}

}  // namespace stepbench::cli

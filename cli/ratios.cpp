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
#include "study/study_reader.hpp"

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
json step_costs(const study_problem& p, const std::vector<std::string>& names) {
  std::vector<const study_method*> ms;
  for (const auto& n : names)
    if (const auto* m = p.find(n)) ms.push_back(m);
  if (ms.empty() || !ms.front()->columns.count("time_ns")) return nullptr;
  const auto& ladder = ms.front()->col("param");
  for (std::size_t k = ladder.size(); k-- > 0;) {
    json row = {{"problem", p.name},
                {"dt", ladder[k]},
                {"ns_per_step", json::object()},
                {"force_evals_per_step", json::object()}};
    bool all = true;
    for (const auto* m : ms) {
      const auto& param = m->col("param");
      const auto it = std::find(param.begin(), param.end(), ladder[k]);
      const std::size_t i = static_cast<std::size_t>(it - param.begin());
      if (it == param.end() || !std::isfinite(m->col("time_ns")[i])) {
        all = false;
        break;
      }
      row["ns_per_step"][m->name] = m->col("time_ns")[i] / m->col("steps")[i];
      row["force_evals_per_step"][m->name] = m->col("force_evals")[i] / m->col("steps")[i];
    }
    if (all) return row;
  }
  return nullptr;
}

// ns per right-hand-side call of each named method: the median over its timed rows of
// time / force evaluations (one figure per method, robust to the rows' spread).
json ns_per_call(const study_problem& p, const std::vector<std::string>& names) {
  json out = json::object();
  for (const auto& n : names) {
    const auto* m = p.find(n);
    if (!m || !m->columns.count("time_ns")) continue;
    std::vector<double> v;
    const auto &t = m->col("time_ns"), &f = m->col("force_evals");
    for (std::size_t i = 0; i < t.size(); ++i)
      if (std::isfinite(t[i]) && f[i] > 0) v.push_back(t[i] / f[i]);
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    out[n] = {{"ns_per_call", v[v.size() / 2]}, {"rows", v.size()}, {"library", m->library}};
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

// Cheapest of ours and cheapest peer at a target, among the methods that were timed.
json equal_error(const study_problem& p, double target, const std::string& metric) {
  std::vector<wp_method> methods;
  for (auto& m : work_precision_input(p, metric, true)) {
    bool timed = false;
    for (const auto& r : m.rows) timed = timed || std::isfinite(r.time_ns);
    if (timed) methods.push_back(std::move(m));
  }
  const auto r = cheapest(methods, target, true, metric, p.unit);
  json out = {{"problem", p.name}, {"metric", metric}, {"target", target}, {"cost", r.cost}, {"ranked", json::array()}};
  const wp_pick *ours = nullptr, *peer = nullptr;
  for (const auto& pick : r.ranked) {
    const auto& m = methods[pick.method];
    const auto& row = m.rows[pick.row];
    out["ranked"].push_back({{"method", m.name},
                             {"origin", to_string(m.origin)},
                             {"param", row.param},
                             {"time_ns", row.time_ns},
                             {"error", row.error}});
    if (m.origin == method_origin::ours && !ours) ours = &pick;
    if (m.origin == method_origin::peer && !peer) peer = &pick;
  }
  auto named = [&](const wp_pick* pick) {
    return pick ? json{{"method", methods[pick->method].name}, {"time_ns", pick->cost}} : json(nullptr);
  };
  out["ours"] = named(ours);
  out["peer"] = named(peer);
  out["peer_over_ours"] = ours && peer && r.cost == "time_ns" ? json(peer->cost / ours->cost) : json(nullptr);
  out["ours_over_peer"] = ours && peer && r.cost == "time_ns" ? json(ours->cost / peer->cost) : json(nullptr);
  out["target_0_5"] = verdict(out["ours_over_peer"].is_null() ? NAN : out["ours_over_peer"].get<double>());
  return out;
}

int run_ratios(const ratios_args& a) {
  const study_data s = read_study(a.study);
  if (!s.timed) throw std::runtime_error(fmt::format("{} has no timings: run stepbench_bench --study_out", a.study));
  json out = {{"study", a.study}, {"cpu", s.meta.count("cpu") ? s.meta.at("cpu") : ""}};
  if (const auto* spring = s.find("damped_spring"))
    out["step_cost"] = step_costs(*spring, {"rk4", "baseline_rk4", "gsl_rk4", "odeint_rk4"});
  out["step_cost_rk8"] = json::array();
  out["ns_per_rhs_call"] = json::array();
  for (const auto& name : a.problems)
    if (const auto* p = s.find(name)) {
      // The eighth-order fixed steps at the finest dt where all were timed: ours, the
      // hand-written floor, and the libraries' (Odeint's only where Boost is present).
      std::vector<std::string> names{"rk8", "baseline_rk8", "gsl_rk8pd", "arkode_erk8"};
      if (p->find("odeint_rkf78")) names.push_back("odeint_rkf78");
      if (auto sc = step_costs(*p, names); !sc.is_null()) out["step_cost_rk8"].push_back(sc);
      out["ns_per_rhs_call"].push_back(
          {{"problem", p->name},
           {"methods", ns_per_call(*p, {"gsl_rk8pd_adaptive", "gsl_rkf45_adaptive", "arkode_erk8_adaptive",
                                        "arkode_erk5_adaptive", "cvode_adams", "cvode_bdf", "gsl_rk8pd", "arkode_erk8",
                                        "odeint_rkf78_adaptive", "odeint_bulirsch_stoer"})}});
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
        out["order_notes"].push_back(
            {{"problem", p.name}, {"method", m.name}, {"declared", m.declared_order}, {"observed", m.fit_slope}});
  if (a.json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }

  fmt::print("Performance ratios from {} ({}; each figure measured in that one run)\n", a.study,
             out["cpu"].get<std::string>());
  if (const auto& sc = out["step_cost"]; !sc.is_null()) {
    const auto& ns = sc["ns_per_step"];
    fmt::print("\nStep cost, {} at dt = {:.6g} s (ns per step):", sc["problem"].get<std::string>(),
               sc["dt"].get<double>());
    for (const auto& [k, v] : ns.items()) fmt::print("  {} {:.2f}", k, v.get<double>());
    fmt::print("\n");
    auto ratio = [&](const char* x, const char* y, const char* target, auto ok) {
      if (!ns.contains(x) || !ns.contains(y)) return;
      const double r = ns[x].get<double>() / ns[y].get<double>();
      fmt::print("  {:<28} {:>6.2f}   target {} {}\n", fmt::format("{} / {}", x, y), r, target,
                 ok(r) ? "met" : "NOT MET");
    };
    ratio("rk4", "baseline_rk4", "<= 1.15", [](double r) { return r <= 1.15; });
    ratio("gsl_rk4", "rk4", ">= 6", [](double r) { return r >= 6.0; });
    if (sc["force_evals_per_step"].contains("gsl_rk4"))
      fmt::print(
          "    (GSL's rk4 estimates its error by step doubling: {:.2f} force evaluations a step against our 4)\n",
          sc["force_evals_per_step"]["gsl_rk4"].get<double>());
    ratio("rk4", "odeint_rk4", "<= 0.85", [](double r) { return r <= 0.85; });
  } else {
    fmt::print("\nStep cost: rk4 and its peers on damped_spring were not all timed\n");
  }
  for (const auto& sc : out["step_cost_rk8"]) {
    const auto& ns = sc["ns_per_step"];
    const auto& fe = sc["force_evals_per_step"];
    fmt::print("\nStep cost, eighth order, {} at dt = {:.6g} s (ns per step; force evaluations a step):\n ",
               sc["problem"].get<std::string>(), sc["dt"].get<double>());
    for (const auto& [k, v] : ns.items()) fmt::print("  {} {:.1f} ({:.2f})", k, v.get<double>(), fe[k].get<double>());
    fmt::print("\n");
    auto ratio = [&](const char* x, const char* y, const char* target, auto ok) {
      if (!ns.contains(x) || !ns.contains(y)) return;
      const double r = ns[x].get<double>() / ns[y].get<double>();
      fmt::print("  {:<28} {:>6.2f}{}\n", fmt::format("{} / {}", x, y), r,
                 target ? fmt::format("   target {} {}", target, ok(r) ? "met" : "NOT MET") : std::string());
    };
    ratio("rk8", "baseline_rk8", "<= 1.15", [](double r) { return r <= 1.15; });
    ratio("gsl_rk8pd", "rk8", nullptr, [](double) { return true; });
    ratio("odeint_rkf78", "rk8", nullptr, [](double) { return true; });
    ratio("arkode_erk8", "rk8", nullptr, [](double) { return true; });
  }
  if (!out["ns_per_rhs_call"].empty()) {
    fmt::print("\nns per right-hand-side call (median over the timed rows of time / force evaluations):\n");
    for (const auto& e : out["ns_per_rhs_call"]) {
      fmt::print("  {:<15}", e["problem"].get<std::string>());
      for (const auto& [k, v] : e["methods"].items()) fmt::print("  {} {:.1f}", k, v["ns_per_call"].get<double>());
      fmt::print("\n");
    }
  }
  fmt::print("\nEqual error: time to reach err_pos_max (cheapest measured row that reaches it; the study's rule)\n");
  fmt::print("  {:<15} {:>7}  {:<34} {:<34} {:>11} {:>11}  {}\n", "problem", "target", "cheapest of ours",
             "cheapest peer", "peer / ours", "ours / peer", "target <= 0.5");
  auto who = [](const json& j) {
    return j.is_null()
               ? std::string("none reaches it")
               : fmt::format("{} {}", j["method"].get<std::string>(), format_time_ns(j["time_ns"].get<double>()));
  };
  for (const auto& e : out["equal_error"])
    fmt::print("  {:<15} {:>7.0e}  {:<34} {:<34} {:>11} {:>11}  {}\n", e["problem"].get<std::string>(),
               e["target"].get<double>(), who(e["ours"]), who(e["peer"]),
               e["peer_over_ours"].is_null() ? "-" : fmt::format("{:.2f}", e["peer_over_ours"].get<double>()),
               e["ours_over_peer"].is_null() ? "-" : fmt::format("{:.2f}", e["ours_over_peer"].get<double>()),
               e["target_0_5"].get<std::string>());
  std::string open;
  for (const auto& e : out["equal_error"])
    if (e["target_0_5"] == "OPEN")
      open += fmt::format("{}{} at {:.0e}", open.empty() ? "" : ", ", e["problem"].get<std::string>(),
                          e["target"].get<double>());
  fmt::print("  open (ours / peer >= 1.0): {}\n", open.empty() ? "none" : open);
  for (const auto& e : out["equal_error"]) {
    if (e["problem"] != "pendulum" || e["target"].get<double>() != 1e-6) continue;
    fmt::print("\n  pendulum, every method to err_pos_max = 1e-6:\n");
    for (const auto& r : e["ranked"])
      fmt::print("    {:<24} {:>10}  {} {:g}{}\n", r["method"].get<std::string>(),
                 format_time_ns(r["time_ns"].get<double>()), r["origin"] == "ours" ? "ours," : "",
                 r["param"].get<double>(), r["origin"] == "baseline" ? "  (baseline, for scale)" : "");
  }
  if (const auto& f = out["equal_error_final"]; !f.is_null())
    fmt::print("\n  pendulum to err_pos_final = 1e-6 instead: cheapest of ours {}, cheapest peer {}\n", who(f["ours"]),
               who(f["peer"]));
  for (const auto& n : out["order_notes"])
    fmt::print("  note: {} on {} declares order {:g} but achieves {:.2f}\n", n["method"].get<std::string>(),
               n["problem"].get<std::string>(), n["declared"].get<double>(), n["observed"].get<double>());
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

// `stepbench list [--json]`: the problems with their parameters, and every method (ours,
// the peers, the baseline) with its order and capabilities.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "parts/part.hpp"
#include "registry/plugins.hpp"
#include "registry/registry.hpp"
#include "render/table_render.hpp"

namespace stepbench {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(capabilities, symplectic, reuses_last_force, needs_jacobian, error_estimate,
                                   dense_output)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(named_value, name, value, description)
}  // namespace stepbench

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

// The text form of the listing: the problems, their parameters, and the methods by origin,
// each a table.
void print_list(const json& out) {
  table problems{{{"problem"}, right_column("dim"), right_column("horizon", "s"), {"closed form"}, {"description"}},
                 {}};
  table params{{{"problem"}, {"parameter"}, right_column("default"), {"unit"}, {"allowed"}, {"description"}}, {}};
  // A long list of names (the lecture's friction table, taken by both sliding blocks) is
  // printed once, after the parameters.
  std::map<std::string, json> long_lists;
  for (const auto& p : out["problems"]) {
    const std::string name = p["name"].get<std::string>();
    problems.add({name, std::to_string(p["dim"].get<int>()), fmt::format("{:.6g}", p["horizon"].get<double>()),
                  p["closed_form"].get<bool>() ? "yes" : "no", p["description"].get<std::string>()});
    for (const auto& q : p["parameters"]) {
      const auto& names = q["names"];
      std::string allowed = q["allowed"].get<std::string>();
      if (!names.empty() && names.size() <= 4) {
        std::vector<std::string> options;
        for (const auto& n : names)
          options.push_back(fmt::format("{:g} {}", n["value"].get<double>(), n["name"].get<std::string>()));
        allowed = fmt::format("{}", fmt::join(options, ", "));
      } else if (!names.empty()) {
        allowed += ", or a name below";
        long_lists.try_emplace(q["name"].get<std::string>(), names);
      }
      params.add({name, q["name"].get<std::string>(), fmt::format("{:g}", q["default"].get<double>()),
                  q["unit"].get<std::string>(), allowed, q["description"].get<std::string>()});
    }
  }
  fmt::print("problems:\n{}\nparameters:\n{}", render_text(problems), render_text(params));
  for (const auto& [param, names] : long_lists) {
    table named{{right_column("value"), {"name"}, {"meaning"}}, {}};
    for (const auto& n : names)
      named.add({fmt::format("{:g}", n["value"].get<double>()), n["name"].get<std::string>(),
                 n["description"].get<std::string>()});
    fmt::print("\nnames {} takes:\n{}", param, render_text(named));
  }
  for (const auto origin : {method_origin::ours, method_origin::peer, method_origin::baseline, method_origin::plugin}) {
    if (origin == method_origin::plugin && plugin_methods().empty()) continue;  // list --plugin PATH shows them
    table methods{
        {{"method"}, {"kind"}, right_column("order"), right_column("evals/step"), {"description"}, {"capabilities"}},
        {}};
    for (const auto& m : all_methods()) {
      if (m.origin != origin) continue;
      std::string caps;
      const json declared = m.traits;  // named: items() of a temporary would dangle
      for (const auto& [key, on] : declared.items())
        if (on.get<bool>()) caps += (caps.empty() ? "" : ", ") + key;
      methods.add({m.name, std::string(to_string(m.kind)),
                   std::isfinite(m.declared_order) ? fmt::format("{:g}", m.declared_order) : "-",
                   std::isfinite(m.evals_per_step) ? fmt::format("{:g}", m.evals_per_step) : "-", m.description, caps});
    }
    fmt::print("\n{}:\n{}",
               origin == method_origin::ours     ? "integrators (ours)"
               : origin == method_origin::peer   ? "peers"
               : origin == method_origin::plugin ? "plugins (docs/plugins.md)"
                                                 : "baseline (for scale, never recommended)",
               render_text(methods));
    // Methods that run on only some problems (xpbd: the scenes with a constraint view;
    // Odeint: a state size known at compile time), grouped by the problems they run on.
    std::vector<std::pair<std::string, std::vector<std::string>>> limited;  // problems, methods
    for (const auto& m : out["methods"]) {
      if (m["origin"].get<std::string>() != to_string(origin)) continue;
      const auto on = m["runs_on"].get<std::vector<std::string>>();
      if (on.size() == out["problems"].size()) continue;
      // Whichever is shorter: the problems it runs on, or those it does not.
      std::vector<std::string> off;
      for (const auto& p : out["problems"])
        if (std::ranges::find(on, p["name"].get<std::string>()) == on.end()) off.push_back(p["name"]);
      const std::string where = on.empty() ? std::string("runs on no problem")
                                : on.size() <= off.size()
                                    ? fmt::format("only on {}", fmt::join(on, ", "))
                                    : fmt::format("on every problem but {}", fmt::join(off, ", "));
      auto it = std::find_if(limited.begin(), limited.end(), [&](const auto& e) { return e.first == where; });
      if (it == limited.end()) limited.push_back({where, {}}), it = limited.end() - 1;
      it->second.push_back(m["name"].get<std::string>());
    }
    for (const auto& [where, names] : limited) fmt::print("  {}: {}\n", fmt::join(names, ", "), where);
  }
  fmt::print("\nParts of the study, in the order a study runs them (sweep --parts A,B runs only those):\n");
  for (const auto& p : out["parts"])
    fmt::print("  {:<12} {}\n", p["name"].get<std::string>(), p["summary"].get<std::string>());
  std::vector<std::string> presets;
  for (const auto& p : out["presets"])
    presets.push_back(fmt::format("{} ({})", p["name"].get<std::string>(), p["summary"].get<std::string>()));
  fmt::print("Presets: {}\n", fmt::join(presets, "; "));
}

int run_list(bool as_json) {
  json out;
  for (const auto& name : problem_names()) {
    auto p = make_problem(name);
    json params = json::array();
    for (const auto& q : p->params())
      params.push_back({{"name", q.name},
                        {"default", q.default_value},
                        {"unit", q.unit},
                        {"description", q.description},
                        {"kind", q.kind()},
                        {"allowed", q.allowed.text()},
                        {"names", q.names}});
    json methods = json::array();
    for (const auto& m : p->methods()) methods.push_back(m.name);
    out["problems"].push_back({{"name", name},
                               {"description", p->description()},
                               {"dim", p->dim()},
                               {"position_unit", p->position_unit()},
                               {"horizon", p->horizon()},
                               {"closed_form", p->has_closed_form()},
                               {"energy", p->has_energy()},
                               {"jacobian", p->has_jacobian()},
                               {"parameters", params},
                               {"methods", methods}});
  }
  for (const auto& m : all_methods()) {
    json runs_on = json::array();
    for (const auto& p : out["problems"])
      if (std::ranges::find(p["methods"], json(m.name)) != p["methods"].end()) runs_on.push_back(p["name"]);
    out["methods"].push_back({{"name", m.name},
                              {"description", m.description},
                              {"origin", to_string(m.origin)},
                              {"kind", to_string(m.kind)},
                              {"library", m.library},
                              {"capabilities", m.traits},
                              {"declared_order", m.declared_order},  // NaN is written as null
                              {"evals_per_step", m.evals_per_step},
                              {"runs_on", runs_on}});
  }
  for (const auto& p : study_parts()) out["parts"].push_back({{"name", p.name}, {"summary", p.summary}});
  for (const auto& p : study_presets()) out["presets"].push_back({{"name", p.name}, {"summary", p.summary}});
  if (as_json)
    std::cout << out.dump(2) << "\n";
  else
    print_list(out);
  return 0;
}

}  // namespace

command add_list(CLI::App& app) {
  auto* sub = app.add_subcommand("list", "list problems (with parameters) and methods (with orders and capabilities)");
  auto as_json = std::make_shared<bool>(false);
  sub->add_flag("--json", *as_json, "print JSON");
  return {sub, [as_json] { return run_list(*as_json); }};
}

}  // namespace stepbench::cli

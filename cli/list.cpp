// `stepbench list [--json]`: the problems with their parameters, and every method (ours,
// the peers, the baseline) with its order and capabilities.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "study/registry.hpp"

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

json capabilities_json(const capabilities& c) {
  return {{"symplectic", c.symplectic},
          {"reuses_last_force", c.reuses_last_force},
          {"needs_jacobian", c.needs_jacobian},
          {"error_estimate", c.error_estimate},
          {"dense_output", c.dense_output}};
}

int run_list(bool as_json) {
  json out;
  for (const auto& name : problem_names()) {
    auto p = make_problem(name);
    json params = json::array();
    for (const auto& q : p->params()) {
      json names = json::array();
      for (const auto& n : q.names)
        names.push_back({{"name", n.name}, {"value", n.value}, {"description", n.description}});
      params.push_back({{"name", q.name},
                        {"default", q.default_value},
                        {"unit", q.unit},
                        {"description", q.description},
                        {"kind", q.kind()},
                        {"allowed", q.allowed.text()},
                        {"names", names}});
    }
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
    json j = {{"name", m.name},
              {"description", m.description},
              {"origin", to_string(m.origin)},
              {"kind", to_string(m.kind)},
              {"library", m.library},
              {"capabilities", capabilities_json(m.traits)}};
    j["declared_order"] = std::isfinite(m.declared_order) ? json(m.declared_order) : json(nullptr);
    out["methods"].push_back(j);
  }
  if (as_json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::map<std::string, json> long_lists;
  fmt::print("problems:\n");
  for (const auto& p : out["problems"]) {
    fmt::print("  {:<22} {} (dim {}, horizon {:.6g} s{})\n", p["name"].get<std::string>(),
               p["description"].get<std::string>(), p["dim"].get<int>(), p["horizon"].get<double>(),
               p["closed_form"].get<bool>() ? ", closed form" : "");
    for (const auto& q : p["parameters"]) {
      const auto& names = q["names"];
      // A long list of names (the lecture's friction table) is printed once, below.
      std::string allowed = q["allowed"].get<std::string>();
      if (!names.empty() && names.size() <= 4) {
        std::vector<std::string> options;
        for (const auto& n : names)
          options.push_back(fmt::format("{:g} {}", n["value"].get<double>(), n["name"].get<std::string>()));
        allowed = fmt::format("{}", fmt::join(options, ", "));
      } else if (!names.empty()) {
        allowed += fmt::format(", or one of the {} names below", names.size());
        long_lists.try_emplace(q["name"].get<std::string>(), names);
      }
      fmt::print("      {:<14} = {:<10g} [{}] {} ({})\n", q["name"].get<std::string>(), q["default"].get<double>(),
                 q["unit"].get<std::string>(), q["description"].get<std::string>(), allowed);
    }
  }
  for (const auto& [param, names] : long_lists) {
    fmt::print("names {} takes:\n", param);
    for (const auto& n : names)
      fmt::print("  {:>4g}  {:<40} {}\n", n["value"].get<double>(), n["name"].get<std::string>(),
                 n["description"].get<std::string>());
  }
  for (const auto origin : {method_origin::ours, method_origin::peer, method_origin::baseline}) {
    fmt::print("{}:\n", origin == method_origin::ours   ? "integrators (ours)"
                        : origin == method_origin::peer ? "peers"
                                                        : "baseline (for scale, never recommended)");
    for (const auto& m : all_methods()) {
      if (m.origin != origin) continue;
      std::string caps;
      const json declared = capabilities_json(m.traits);
      for (const auto& [key, on] : declared.items())
        if (on.get<bool>()) caps += (caps.empty() ? "" : ", ") + key;
      fmt::print("  {:<24} {:<10} order {:<4} {}{}\n", m.name, to_string(m.kind),
                 std::isfinite(m.declared_order) ? fmt::format("{:g}", m.declared_order) : "-", m.description,
                 caps.empty() ? "" : " [" + caps + "]");
    }
  }
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

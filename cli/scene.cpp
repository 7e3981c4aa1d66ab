// `stepbench scene check FILE [--json]`: reads and checks a scene file (docs/scenes.md) and
// says what it holds: the masses, the force elements, the parameters a command's --set
// takes, and how stiff it is (the fastest frequency at the start, against a frame).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "registry/registry.hpp"
#include "registry/scenes.hpp"

namespace stepbench::cli {
namespace {

using json = nlohmann::json;

struct scene_args {
  std::string path;
  bool json = false;
};

int run_scene_check(const scene_args& a) {
  const std::string name = load_scene(a.path);  // throws one line for a bad file
  const loaded_scene& sc = *find_scene(name);
  const scene_data& d = *sc.data;
  const auto problem = make_problem(name);
  if (auto why = problem->validate(); !why.empty()) throw std::invalid_argument(fmt::format("{}: {}", a.path, why));
  const int moving = d.moving(), fixed = static_cast<int>(d.masses.size()) - moving;
  double total = 0.0;
  for (double m : d.moving_mass) total += m;
  std::vector<std::string> elements;
  if (!d.springs.empty()) elements.push_back(count_of(static_cast<long long>(d.springs.size()), "spring"));
  if (d.has_gravity) elements.push_back("gravity");
  if (d.has_drag) elements.push_back("drag");
  if (d.has_attraction) elements.push_back("attraction");
  if (!d.planes.empty()) elements.push_back(count_of(static_cast<long long>(d.planes.size()), "plane"));
  const double w = problem->fastest_frequency();
  json out{{"file", a.path},
           {"name", name},
           {"fnv1a_64", sc.fnv1a_64},
           {"dim", d.dim},
           {"horizon_s", d.horizon},
           {"masses", d.masses.size()},
           {"moving", moving},
           {"fixed", fixed},
           {"moving_mass_kg", total},
           {"springs", d.springs.size()},
           {"gravity", d.has_gravity},
           {"drag", d.has_drag},
           {"attraction", d.has_attraction},
           {"planes", d.planes.size()},
           {"contact_mode", problem->contact_mode()},
           {"state_size", 2 * problem->dim()},
           {"energy_J", problem->energy(problem->initial())},
           {"fastest_frequency_rad_s", w},
           {"methods", problem->methods().size()}};
  json params = json::array();
  for (const auto& q : problem->params())
    params.push_back({{"name", q.name}, {"value", q.value}, {"unit", q.unit}, {"description", q.description}});
  out["parameters"] = params;
  if (a.json) {
    print_answer(true, out, "");
    return 0;
  }
  std::string text = fmt::format(
      "{}: valid: scene '{}', {}-D, {} ({} moving, {} fixed), {}; horizon {:g} s\n", a.path, name, d.dim,
      fmt::format("{} mass{}", d.masses.size(), d.masses.size() == 1 ? "" : "es"), moving, fixed,
      elements.empty() ? std::string("no forces") : fmt::format("{}", fmt::join(elements, ", ")), d.horizon);
  text += fmt::format(
      "  state: {} coordinates ({} a moving mass, positions and velocities); {:g} kg moving; energy {:.6g} J\n",
      2 * problem->dim(), 2 * d.dim, total, problem->energy(problem->initial()));
  if (w > 0.0)
    text += fmt::format(
        "  stiffness: fastest frequency {:.4g} rad/s at the start (a Gershgorin bound); one 60 Hz frame is "
        "w dt = {:.3g} (on an undamped mode explicit RK4 is stable to 2.83, semi-implicit Euler to 2)\n",
        w, w / 60.0);
  text += fmt::format("  {} methods run on it; --set {}.NAME=VALUE takes:", problem->methods().size(), name);
  for (const auto& q : problem->params())
    text += fmt::format(" {}={:g}{}", q.name, q.value, q.unit == "1" ? "" : " " + q.unit);
  text += fmt::format("\n  next: stepbench advise --scene {} --hz 60 --tol 1e-3\n", a.path);
  fmt::print("{}", text);
  return 0;
}

}  // namespace

command add_scene(CLI::App& app) {
  auto a = std::make_shared<scene_args>();
  auto* sub = app.add_subcommand("scene", "scene files (docs/scenes.md): check one");
  sub->require_subcommand(1);
  auto* check =
      sub->add_subcommand("check", "read and check a scene file and summarise it (exit 2 and one line if bad)");
  check->add_option("file", a->path, "the scene file")->required();
  check->add_flag("--json", a->json, "print JSON");
  return {sub, [a] { return run_scene_check(*a); }};
}

}  // namespace stepbench::cli

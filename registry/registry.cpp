#include "registry/registry.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>
#include <stdexcept>

#include "integrators/all.hpp"
#include "peers/all.hpp"
#include "problem_entries.hpp"     // generated from STEPBENCH_PROBLEMS (CMakeLists.txt)
#include "problem_tags_check.hpp"  // the same list's tags, checked against the method groups
#include "registry/method_entry.hpp"
#include "registry/scenes.hpp"

namespace stepbench {

using namespace registry_detail;

std::vector<std::string> builtin_problem_names() {
  std::vector<std::string> names;
  for (const auto entry : problem_entries) names.emplace_back(entry().name);
  return names;
}

std::vector<std::string> problem_names() {
  std::vector<std::string> names = builtin_problem_names();
  for (const auto& s : loaded_scenes()) names.push_back(s.name);
  return names;
}

std::unique_ptr<problem_instance> make_problem(std::string_view name) {
  for (const auto entry : problem_entries)
    if (const problem_entry e = entry(); e.name == name) return e.make();
  if (const loaded_scene* s = find_scene(name)) return make_scene_problem(s->data);
  throw std::invalid_argument(fmt::format("unknown problem '{}' (known: {})", name, fmt::join(problem_names(), ", ")));
}

namespace {
std::vector<method_info>& registered_methods() {
  static std::vector<method_info> all = [] {
    std::vector<method_info> out;
    // Ours, then the peers: the registry's order (the study file's, `stepbench list`'s).
    for_each_type(type_list_cat_t<all_ours, all_peers>{}, [&]<class M>() { out.push_back(info_of<entry_t<M>>()); });
    return out;
  }();
  return all;
}
}  // namespace

const std::vector<method_info>& all_methods() { return registered_methods(); }

void registry_detail::register_method(const method_info& m) { registered_methods().push_back(m); }

const method_info* registered_method(std::string_view name) {
  for (const auto& m : all_methods())
    if (m.name == name) return &m;
  return nullptr;
}

const method_info& find_method(std::string_view name) {
  if (const method_info* m = registered_method(name)) return *m;
  std::vector<std::string> known;
  for (const auto& m : all_methods()) known.push_back(m.name);
  throw std::invalid_argument(fmt::format("unknown method '{}' (known: {})", name, fmt::join(known, ", ")));
}

}  // namespace stepbench

#pragma once
// The registries behind the command line and the benchmark: the one place where
// problems and methods are type-erased. A problem_instance owns one problem value with
// its parameters; its run() dispatches to the loop instantiated for that problem and
// the named method (ours, a peer, the baseline), so no step loop makes a virtual call.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/problem_instance.hpp"

namespace stepbench {

// The built-in problems, then the scenes loaded from files (registry/scenes.hpp).
std::vector<std::string> problem_names();
std::vector<std::string> builtin_problem_names();
// Throws std::invalid_argument naming the unknown problem and the known ones.
std::unique_ptr<problem_instance> make_problem(std::string_view name);

// Every method in registry order: our integrators, then the peers and the baseline, then
// the plugins' methods in the order they were loaded (registry/plugins.hpp).
const std::vector<method_info>& all_methods();
// Throws std::invalid_argument naming the unknown method and the known ones.
const method_info& find_method(std::string_view name);
// The method of that name, or nullptr (a study file may hold a method this build lacks).
const method_info* registered_method(std::string_view name);

namespace registry_detail {
// Appends a plugin's method to all_methods() (registry/plugins.cpp, before anything runs).
void register_method(const method_info& m);
}  // namespace registry_detail

}  // namespace stepbench

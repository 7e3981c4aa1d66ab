// The unit of the scenes with walls: problem_model<contact_scene> (registry/problem_model.hpp)
// over the methods that run on a problem with contacts: the groups of CMakeLists.txt's
// STEPBENCH_METHOD_GROUPS that do not exclude `contacts` (the peers and the Verner pairs
// do; append_group keeps only the methods that run on it).
#include "integrators/group_adaptive_high_order.hpp"
#include "integrators/group_explicit.hpp"
#include "integrators/group_implicit.hpp"
#include "problems/scene.hpp"
#include "registry/method_table.hpp"
#include "registry/problem_model.hpp"
#include "registry/scenes.hpp"

namespace stepbench::registry_detail {

std::unique_ptr<problem_instance> make_contact_scene_problem(std::shared_ptr<const scene_data> data) {
  static const method_table<contact_scene> methods = [] {
    method_table<contact_scene> table;
    append_group(explicit_integrators{}, table);
    append_group(implicit_integrators{}, table);
    append_group(adaptive_high_order_integrators{}, table);
    sort_by_registry_order(table);
    return table;
  }();
  return std::make_unique<problem_model<contact_scene>>(methods, contact_scene(std::move(data)));
}

}  // namespace stepbench::registry_detail

// The scenes' unit: problem_model<scene> (registry/problem_model.hpp) over the methods
// that run on a scene: every group's whose tags a smooth problem without a constraint
// view has (CMakeLists.txt's STEPBENCH_METHOD_GROUPS; append_group keeps only the methods
// that run on it). Like a generated problem unit, one unit: the method groups are parsed
// and instantiated once, for every scene file.
#include "integrators/group_adaptive_high_order.hpp"
#include "integrators/group_explicit.hpp"
#include "integrators/group_implicit.hpp"
#include "integrators/group_verner.hpp"
#include "peers/group_adaptive.hpp"
#include "peers/group_fixed.hpp"
#include "problems/scene.hpp"
#include "registry/method_table.hpp"
#include "registry/problem_model.hpp"
#include "registry/scenes.hpp"

namespace stepbench::registry_detail {

std::unique_ptr<problem_instance> make_smooth_scene_problem(std::shared_ptr<const scene_data> data) {
  static const method_table<scene> methods = [] {
    method_table<scene> table;
    append_group(explicit_integrators{}, table);
    append_group(implicit_integrators{}, table);
    append_group(adaptive_high_order_integrators{}, table);
    append_group(verner_integrators{}, table);
    append_group(fixed_step_peers{}, table);
    append_group(adaptive_peers{}, table);
    sort_by_registry_order(table);
    return table;
  }();
  return std::make_unique<problem_model<scene>>(methods, scene(std::move(data)));
}

}  // namespace stepbench::registry_detail

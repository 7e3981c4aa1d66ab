#pragma once
// Our position-based methods (XPBD), one group of the integrator registry
// (integrators/all.hpp), compiled in its own unit per problem. They run only on problems
// with a constraint view (core/constraints.hpp), on the fixed-step loop the peers use
// (core/step_adapter.hpp): they step particles, not the problem's forces.
#include "core/step_adapter.hpp"
#include "core/type_list.hpp"
#include "integrators/xpbd.hpp"

namespace stepbench {

using constraint_integrators = type_list<peers::fixed_step_peer<xpbd>, peers::fixed_step_peer<xpbd_iterations>>;

}  // namespace stepbench

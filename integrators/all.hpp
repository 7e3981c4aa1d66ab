#pragma once
// The integrator registry: adding an integrator is its header plus one entry in its
// group's list (integrators/group_*.hpp). The registry's order is the groups' in turn.
// Fixed-step methods run over the dt ladder, adaptive ones over the tolerance ladder.
#include "core/type_list.hpp"
#include "integrators/group_adaptive_high_order.hpp"
#include "integrators/group_constraint.hpp"
#include "integrators/group_explicit.hpp"
#include "integrators/group_implicit.hpp"
#include "integrators/group_verner.hpp"

namespace stepbench {

// The force-based integrators (the stability study steps each on its test equations).
using all_integrators =
    type_list_cat_t<explicit_integrators, implicit_integrators, adaptive_high_order_integrators, verner_integrators>;

// Every method of ours: the force-based ones, then the position-based ones, which step a
// problem's constraint view (core/constraints.hpp), not its forces.
using all_ours = type_list_cat_t<all_integrators, constraint_integrators>;

}  // namespace stepbench

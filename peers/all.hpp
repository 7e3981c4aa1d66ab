#pragma once
// The peer registry: what a user might run instead of our integrators, on the same
// problems, measured by the same code. Adding a peer is its header (a descriptor and a
// step adapter, core/step_adapter.hpp) plus one entry in its group's list
// (peers/group_*.hpp). The registry's order is the groups' in turn.
#include "core/type_list.hpp"
#include "peers/group_adaptive.hpp"
#include "peers/group_fixed.hpp"

namespace stepbench {

using all_peers = type_list_cat_t<fixed_step_peers, adaptive_peers>;

}  // namespace stepbench

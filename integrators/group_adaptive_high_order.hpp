#pragma once
// Our adaptive integrators and the eighth-order fixed-step one (the tableau-fed methods),
// one group of the integrator registry (integrators/all.hpp), compiled in its own unit
// per problem.
#include "core/type_list.hpp"
#include "integrators/adaptive_euler.hpp"
#include "integrators/dop853.hpp"
#include "integrators/rk45.hpp"
#include "integrators/rk8.hpp"

namespace stepbench {

using adaptive_high_order_integrators = type_list<adaptive_euler, rk45, rk8, dop853>;

}  // namespace stepbench

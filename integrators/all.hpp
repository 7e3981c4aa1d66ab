#pragma once
// The integrator registry: adding an integrator is its header plus one entry here.
#include "core/type_list.hpp"
#include "integrators/euler.hpp"
#include "integrators/midpoint.hpp"
#include "integrators/momentum.hpp"
#include "integrators/rk4.hpp"
#include "integrators/semi_implicit_euler.hpp"
#include "integrators/velocity_verlet.hpp"

namespace stepbench {

using all_integrators = type_list<euler, semi_implicit_euler, midpoint, rk4, momentum, velocity_verlet>;

}  // namespace stepbench

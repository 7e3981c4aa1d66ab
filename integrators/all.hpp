#pragma once
// The integrator registry: adding an integrator is its header plus one entry here.
// Fixed-step methods run over the dt ladder, adaptive ones over the tolerance ladder.
#include "core/type_list.hpp"
#include "integrators/adaptive_euler.hpp"
#include "integrators/dop853.hpp"
#include "integrators/euler.hpp"
#include "integrators/forest_ruth.hpp"
#include "integrators/implicit_euler.hpp"
#include "integrators/implicit_midpoint.hpp"
#include "integrators/midpoint.hpp"
#include "integrators/momentum.hpp"
#include "integrators/rk4.hpp"
#include "integrators/rk45.hpp"
#include "integrators/rk8.hpp"
#include "integrators/semi_implicit_euler.hpp"
#include "integrators/velocity_verlet.hpp"

namespace stepbench {

using all_integrators = type_list<euler, semi_implicit_euler, midpoint, rk4, momentum, velocity_verlet, forest_ruth,
                                  implicit_euler, implicit_midpoint, adaptive_euler, rk45, rk8, dop853>;

}  // namespace stepbench

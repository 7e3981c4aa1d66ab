#pragma once
// Our explicit fixed-step integrators, one group of the integrator registry
// (integrators/all.hpp), included by the generated unit of each problem its methods run
// on (registry/problem_unit.cpp.in).
#include "core/type_list.hpp"
#include "integrators/euler.hpp"
#include "integrators/forest_ruth.hpp"
#include "integrators/midpoint.hpp"
#include "integrators/momentum.hpp"
#include "integrators/rk4.hpp"
#include "integrators/semi_implicit_euler.hpp"
#include "integrators/velocity_verlet.hpp"

namespace stepbench {

using explicit_integrators =
    type_list<euler, semi_implicit_euler, midpoint, rk4, momentum, velocity_verlet, forest_ruth>;

}  // namespace stepbench

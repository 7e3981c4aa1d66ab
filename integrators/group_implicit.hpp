#pragma once
// Our implicit integrators (a Newton solve a step), one group of the integrator registry
// (integrators/all.hpp), compiled in its own unit per problem.
#include "core/type_list.hpp"
#include "integrators/implicit_euler.hpp"
#include "integrators/implicit_midpoint.hpp"

namespace stepbench {

using implicit_integrators = type_list<implicit_euler, implicit_midpoint>;

}  // namespace stepbench

#pragma once
// Verner's pairs, adaptive and at a fixed step, one group of the integrator registry
// (integrators/all.hpp), compiled into the units of the problems without contacts
// (CMakeLists.txt, STEPBENCH_METHOD_GROUPS): a contact caps any method's order at the
// event (the study's bouncing problems show it with rk45 and dop853), and each pair
// instantiated on a problem costs the build about 3 s.
#include "core/type_list.hpp"
#include "integrators/verner.hpp"

namespace stepbench {

using verner_integrators = type_list<vern7, vern9, vern7_fixed, vern9_fixed>;

}  // namespace stepbench

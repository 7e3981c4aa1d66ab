#pragma once
// The fixed-step peers and the baselines, one group of the peer registry (peers/all.hpp),
// included by the generated unit of each problem they run on (registry/problem_unit.cpp.in).
#include "core/type_list.hpp"
#include "peers/arkode_fixed.hpp"
#include "peers/baseline_rk4.hpp"
#include "peers/baseline_rk8.hpp"
#include "peers/gsl_fixed.hpp"
#include "peers/odeint.hpp"

namespace stepbench {

// Each entry: a peer's descriptor and step adapter on the fixed-step loop
// (core/step_adapter.hpp), or a library's whole run (arkode_fixed: the library owns the
// loop, as a user would call it).
using fixed_step_peers =
    type_list<peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rk4_tag>>,
              peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rk2_tag>>,
              peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rkf45_tag>>,
              peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rk8pd_tag>>, peers::arkode_fixed<8>,
              peers::arkode_fixed<5>,
#if STEPBENCH_HAVE_ODEINT
              peers::odeint_rk4, peers::fixed_step_peer<peers::odeint_velocity_verlet>, peers::odeint_rkf78,
#endif
              peers::fixed_step_peer<peers::baseline_rk4>, peers::fixed_step_peer<peers::baseline_rk8>>;

}  // namespace stepbench

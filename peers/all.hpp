#pragma once
// The peer registry: what a user might run instead of our integrators, on the same
// problems, measured by the same code. Adding a peer is its header (a descriptor and a
// step adapter, peers/step_adapter.hpp) plus one entry here.
#include "core/type_list.hpp"
#include "peers/arkode_fixed.hpp"
#include "peers/baseline_rk4.hpp"
#include "peers/baseline_rk8.hpp"
#include "peers/gsl_fixed.hpp"
#include "peers/gsl_rk8pd_fixed.hpp"
#include "peers/library_adaptive.hpp"
#include "peers/odeint.hpp"
#include "peers/odeint_high_order.hpp"

namespace stepbench {

// Each entry: a peer's descriptor and step adapter on the loop its kind runs on
// (peers/step_adapter.hpp), or a library's whole run (library_adaptive, arkode_fixed:
// the library owns the loop, as a user would call it).
using all_peers = type_list<
    peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rk4_tag>>,
    peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rk2_tag>>,
    peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rkf45_tag>>,
    peers::fixed_step_peer<peers::gsl_fixed<peers::gsl_rk8pd_tag>>, peers::arkode_fixed<8>, peers::arkode_fixed<5>,
#if STEPBENCH_HAVE_ODEINT
    peers::odeint_rk4, peers::fixed_step_peer<peers::odeint_velocity_verlet>, peers::odeint_rkf78,
#endif
    peers::fixed_step_peer<peers::baseline_rk4>, peers::fixed_step_peer<peers::baseline_rk8>,
    peers::library_adaptive<peers::gsl_rkf45_solver>, peers::library_adaptive<peers::gsl_rk8pd_solver>,
    peers::library_adaptive<peers::cvode_adams_solver>, peers::library_adaptive<peers::cvode_bdf_solver>,
#if STEPBENCH_HAVE_ODEINT
    peers::adaptive_peer<peers::odeint_adaptive<peers::odeint_dopri5_tag>>,
    peers::adaptive_peer<peers::odeint_adaptive<peers::odeint_rkf78_tag>>,
    peers::adaptive_peer<peers::odeint_adaptive<peers::odeint_bulirsch_stoer_tag>>,
#endif
    peers::library_adaptive<peers::arkode_erk_solver<8>>, peers::library_adaptive<peers::arkode_erk_solver<5>>>;

}  // namespace stepbench

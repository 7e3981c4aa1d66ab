#pragma once
// The peer registry: what a user might run instead of our integrators, on the same
// problems, measured by the same code. Adding a peer is its header plus one entry here.
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

using all_peers = type_list<
    peers::gsl_fixed<peers::gsl_rk4_tag>, peers::gsl_fixed<peers::gsl_rk2_tag>, peers::gsl_fixed<peers::gsl_rkf45_tag>,
    peers::gsl_fixed<peers::gsl_rk8pd_tag>, peers::arkode_fixed<8>, peers::arkode_fixed<5>,
#if STEPBENCH_HAVE_ODEINT
    peers::odeint_rk4, peers::odeint_velocity_verlet, peers::odeint_rkf78,
#endif
    peers::baseline_rk4, peers::baseline_rk8, peers::library_adaptive<peers::gsl_rkf45_solver>,
    peers::library_adaptive<peers::gsl_rk8pd_solver>, peers::library_adaptive<peers::cvode_adams_solver>,
    peers::library_adaptive<peers::cvode_bdf_solver>,
#if STEPBENCH_HAVE_ODEINT
    peers::odeint_adaptive<peers::odeint_dopri5_tag>, peers::odeint_adaptive<peers::odeint_rkf78_tag>,
    peers::odeint_adaptive<peers::odeint_bulirsch_stoer_tag>,
#endif
    peers::library_adaptive<peers::arkode_erk_solver<8>>, peers::library_adaptive<peers::arkode_erk_solver<5>>>;

}  // namespace stepbench

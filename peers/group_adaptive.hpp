#pragma once
// The adaptive peers, one group of the peer registry (peers/all.hpp), included by the
// generated unit of each problem they run on (registry/problem_unit.cpp.in).
#include "core/type_list.hpp"
#include "peers/library_adaptive.hpp"
#include "peers/odeint_high_order.hpp"

namespace stepbench {

// Each entry: a library's whole run (library_adaptive: GSL's driver, CVODE and ARKODE
// own the loop, as a user would call them), or Odeint's stepper on the adaptive loop
// (core/step_adapter.hpp).
using adaptive_peers = type_list<peers::library_adaptive<peers::gsl_solver<gsl_method::rkf45>>,
                                 peers::library_adaptive<peers::gsl_solver<gsl_method::rk8pd>>,
                                 peers::library_adaptive<peers::cvode_solver<cvode_method::adams>>,
                                 peers::library_adaptive<peers::cvode_solver<cvode_method::bdf>>,
#if STEPBENCH_HAVE_ODEINT
                                 peers::adaptive_peer<peers::odeint_adaptive<peers::odeint_dopri5_tag>>,
                                 peers::adaptive_peer<peers::odeint_adaptive<peers::odeint_rkf78_tag>>,
                                 peers::adaptive_peer<peers::odeint_adaptive<peers::odeint_bulirsch_stoer_tag>>,
#endif
                                 peers::library_adaptive<peers::arkode_erk_solver<8>>,
                                 peers::library_adaptive<peers::arkode_erk_solver<5>>>;

}  // namespace stepbench

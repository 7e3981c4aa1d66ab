#pragma once
// GSL's rk8pd stepper (Prince-Dormand 8(7), 13 stages) at our dt, in the same
// gsl_odeiv2_step_apply loop as the other GSL fixed-step peers (peers/gsl_fixed.hpp): the
// library's eighth-order step, for the step-cost comparison with rk8. It computes its
// embedded error estimate at every step, used or not.
#include "peers/gsl_fixed.hpp"

namespace stepbench::peers {

struct gsl_rk8pd_tag {
  static constexpr const char* name = "gsl_rk8pd";
  static constexpr const char* description = "GSL rk8pd (Prince-Dormand 8(7)) at fixed dt (gsl_odeiv2_step_apply)";
  static const gsl_odeiv2_step_type* type() { return gsl_odeiv2_step_rk8pd; }
};

}  // namespace stepbench::peers

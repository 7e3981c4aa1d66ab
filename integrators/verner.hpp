#pragma once
// Verner's "most efficient" 7(6) and 9(8) pairs (integrators/tableaus.hpp, proved in
// tests/test_tableaus.cpp): adaptive, stepping with the higher order (vern7, vern9), and
// the same higher-order solution at a fixed dt (vern7_fixed, vern9_fixed). Neither pair
// is FSAL: an adaptive step costs 10 and 16 evaluations, a fixed step 9 and 15.
//
// Step-size control: Gustafsson's PI controller (integrators/step_control.hpp) with
// beta = 2 / (5 p), p the order of the pair's higher-order solution, as OrdinaryDiffEq.jl
// chooses by default for Vern7 and Vern9 (its PIController with beta2 = 2 / (5 p) and
// beta1 = 7 / (10 p); DiffEqDocs, "Timestepping Method Descriptions"). With p = q + 1,
// q the embedded order, its exponent beta1 is Hairer's 1 / (q + 1) - 0.75 beta: the same
// controller. Safety 0.9, factors 0.2 to 10 (both codes' defaults).
#include <string_view>

#include "integrators/tableau_method.hpp"
#include "integrators/tableaus.hpp"

namespace stepbench {

namespace verner_detail {

constexpr step_controller pi_control(int p) { return {.error_order = p - 1, .beta = 2.0 / (5.0 * p)}; }

// Not on problems with contacts (integrators/group_verner.hpp says why).
struct smooth_problems_only {
  template <class P>
  static constexpr bool applies = !has_contacts<P>;
};

struct vern7_adaptive : smooth_problems_only {
  static constexpr std::string_view name = "vern7";
  static constexpr std::string_view description = "Verner's most efficient 7(6) pair, PI step control";
  static constexpr step_controller control = pi_control(7);
};
struct vern9_adaptive : smooth_problems_only {
  static constexpr std::string_view name = "vern9";
  static constexpr std::string_view description = "Verner's most efficient 9(8) pair, PI step control";
  static constexpr step_controller control = pi_control(9);
};
struct vern7_step : smooth_problems_only {
  static constexpr std::string_view name = "vern7_fixed";
  static constexpr std::string_view description =
      "seventh-order Runge-Kutta: Verner's 7(6) pair's 9-stage step at fixed dt";
};
struct vern9_step : smooth_problems_only {
  static constexpr std::string_view name = "vern9_fixed";
  static constexpr std::string_view description =
      "ninth-order Runge-Kutta: Verner's 9(8) pair's 15-stage step at fixed dt";
};

}  // namespace verner_detail

using vern7 = embedded_pair<vern7_tableau, verner_detail::vern7_adaptive>;
using vern9 = embedded_pair<vern9_tableau, verner_detail::vern9_adaptive>;
using vern7_fixed = fixed_tableau<vern7_tableau, verner_detail::vern7_step>;
using vern9_fixed = fixed_tableau<vern9_tableau, verner_detail::vern9_step>;

}  // namespace stepbench

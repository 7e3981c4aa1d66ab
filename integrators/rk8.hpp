#pragma once
// Eighth-order explicit Runge-Kutta at a fixed step: the step of DOP853 (Dormand &
// Prince; Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., sec. II.6 and dop853.f),
// its 12 stages and eighth-order weights b, without the error estimate. 12 force
// evaluations a step: f(t + h, y_1), DOP853's 13th evaluation, is the next step's first
// stage. Coefficients from integrators/tableaus.hpp (dop853_tableau), proved in
// tests/test_tableaus.cpp; the step is integrators/tableau_method.hpp's fixed_tableau (the
// stages of integrators/unrolled_rk.hpp: 1/m folded, sums unrolled with the newest term
// last, the Nystrom form for a position-only force).
#include <string_view>

#include "integrators/tableau_method.hpp"
#include "integrators/tableaus.hpp"

namespace stepbench {

namespace rk8_detail {
struct descriptor {
  static constexpr std::string_view name = "rk8";
  static constexpr std::string_view description = "eighth-order Runge-Kutta: the 12-stage DOP853 step at fixed dt";
};
}  // namespace rk8_detail

using rk8 = fixed_tableau<dop853_tableau, rk8_detail::descriptor>;

}  // namespace stepbench

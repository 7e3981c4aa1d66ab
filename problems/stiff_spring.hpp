#pragma once
// The damped spring at game-engine stiffness: a 1 kg body on a 1e6 N/m spring with
// light damping (k_d = 20 N s/m: damping ratio k_d / (2 sqrt(k_s m)) = 0.01). Its
// natural frequency w0 = sqrt(k_s / m) = 1000 rad/s makes one 60 Hz frame w0 dt = 16.7,
// far past every explicit method's stability limit (explicit Euler and midpoint are
// unstable at any dt; semi-implicit Euler, velocity Verlet: w dt < 2; RK4: 2.83): what a
// stiff joint or contact spring in a game does to an integrator. The horizon is 32
// frames at 60 Hz (0.533 s, 85 periods), so the coarsest level of the study's ladder is
// exactly the 60 Hz frame. The physics and the closed form are damped_spring's.
#include "problems/damped_spring.hpp"

namespace stepbench {

struct stiff_spring_scene {
  static constexpr std::string_view name = "stiff_spring";
  static constexpr std::string_view description = "1 kg on a 1e6 N/m spring, damping ratio 0.01 (w dt = 16.7 at 60 Hz)";
  static constexpr double k_s = 1e6, k_d = 20.0, mass_kg = 1.0, x0 = 0.01, v0 = 0.0, duration = 32.0 / 60.0;
};
using stiff_spring = spring_damper<stiff_spring_scene>;

}  // namespace stepbench

#pragma once
// Forest & Ruth (Physica D 43 (1990) 105), the same as Yoshida's triple jump (Phys. Lett.
// A 150 (1990) 262): velocity Verlet composed with the weights (w1, w0, w1),
// w1 = 1 / (2 - 2^(1/3)), w0 = -2^(1/3) / (2 - 2^(1/3)) (integrators/tableaus.hpp,
// triple_jump4). Fourth order and symplectic; 3 force evaluations a step with a
// position-only force (integrators/verlet_composition.hpp, which also says what it does
// with a velocity-dependent one). The middle sub-step runs backwards in time (w0 < 0).
#include "core/concepts.hpp"
#include "integrators/tableaus.hpp"
#include "integrators/verlet_composition.hpp"

namespace stepbench {

struct forest_ruth {
  static constexpr std::string_view name = "forest_ruth";
  static constexpr std::string_view description = "Forest-Ruth: Yoshida's triple jump of velocity Verlet, order 4";
  static constexpr int order = 4;
  static constexpr capabilities traits{.symplectic = true, .reuses_last_force = true};
  static constexpr int force_evals_per_step = 3;

  template <class Sys>
  struct stepper : composition_stepper<triple_jump4_kick_drift, Sys> {
    explicit stepper(const forest_ruth&) {}
  };
};

}  // namespace stepbench

#pragma once
// The event-driven truth's default scene (problems/exact/event_driven_balls.hpp), which
// only the tests build: reproducible from a seed, n balls placed by place_on_grid in the
// default box W = 2 m, H = 1 m with r = 0.05 m, g = 9.8, k_r = 1, k_f = 0, m = 1 kg.
// Throws std::invalid_argument when the cells are too small for the balls (n > 171).
#include <cstdint>
#include <stdexcept>

#include "problems/exact/event_driven_balls.hpp"

namespace stepbench::exact {

inline ball_scene default_ball_scene(int n = 16, std::uint64_t seed = 1) {
  ball_scene s;
  if (n < 1) throw std::invalid_argument("default_ball_scene: n must be >= 1");
  s.n = n;
  if (place_on_grid(s, seed) <= 2.0 * s.radius)
    throw std::invalid_argument("default_ball_scene: too many balls for a loose grid in the box");
  return s;
}

}  // namespace stepbench::exact

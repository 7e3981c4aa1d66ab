#pragma once
// The problem registry: adding a problem is its header plus one entry here.
#include "core/type_list.hpp"
#include "problems/bouncing_ball.hpp"
#include "problems/bouncing_balls.hpp"
#include "problems/constant_acceleration.hpp"
#include "problems/damped_spring.hpp"
#include "problems/falling_drag.hpp"
#include "problems/kepler.hpp"
#include "problems/pendulum.hpp"
#include "problems/projectile.hpp"
#include "problems/sliding_block.hpp"
#include "problems/spring_chain.hpp"
#include "problems/stiff_spring.hpp"

namespace stepbench {

using all_problems =
    type_list<constant_acceleration, projectile, damped_spring, pendulum, stiff_spring, spring_chain, kepler,
              falling_drag, sliding_block, sliding_block_stick, bouncing_ball, bouncing_ball_locate, bouncing_balls>;

}  // namespace stepbench

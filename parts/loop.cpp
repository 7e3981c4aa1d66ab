// The game loop around the integrator (/loop): what the player sees, designs, clocks and
// the cost model.
#include "run/loop.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "parts/part.hpp"
#include "store/loop.hpp"

namespace stepbench {

extern const study_part loop_part{
    .name = "loop",
    .summary = "the game loop's designs and clocks: the error the player sees, judder, lag and the spiral of death",
    .describe =
        [](const sweep_options& o) {
          const auto& lp = o.loop;
          return fmt::format(
              "loop: problems {}; methods {}; display {} Hz; physics {} Hz; reference {} Hz; jitter {} seed {}; "
              "clamp {} s; stall {} s at {}; target {}; stated step cost {} ns",
              list_or_all(lp.problems), list_or_all(lp.methods), fmt::join(lp.display_hz, ","),
              fmt::join(lp.physics_hz, ","), lp.reference_display_hz, lp.jitter, lp.jitter_seed, lp.clamp_s, lp.stall_s,
              lp.stall_at_fraction, lp.target, lp.stated_step_cost_ns);
        },
    .run =
        [](study& s, const part_context& ctx) {
          loop_options loop = s.options.loop;
          loop.progress = ctx.progress;
          s.results.put(run_loop_study(s, loop));
        },
    .write = write_loop,
};

}  // namespace stepbench

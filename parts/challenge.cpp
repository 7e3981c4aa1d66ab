// The pendulum challenge and Small Steps (/challenge): one scene, the challenge's own,
// run with n_pendulum at its defaults.
#include "run/challenge.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>

#include "core/contains.hpp"
#include "parts/part.hpp"
#include "run/sweep.hpp"
#include "store/challenge.hpp"

namespace stepbench {

extern const study_part challenge_part{
    .name = "challenge",
    .summary = "Mueller's pendulum challenge: xpbd at 50 substeps against our methods at its time a frame",
    .merge = merge_rule::in_one_shard,
    .describe =
        [](const sweep_options& o) {
          const auto& ch = o.challenge;
          return fmt::format(
              "challenge: {} Hz; xpbd substeps {}; horizon {} s; energy horizon {} s; competitors {}; small steps {} "
              "at {} s",
              ch.hz, ch.xpbd_substeps, ch.horizon, ch.energy_horizon, list_or_all(ch.competitors),
              fmt::join(ch.small_steps_counts, ","), ch.small_steps_time);
        },
    .run =
        [](study& s, const part_context& ctx) {
          const auto& o = s.options;
          if (!contains(ctx.problems, std::string("n_pendulum")) || o.overrides.contains("n_pendulum") ||
              !o.methods.empty())
            return;
          const auto t0 = std::chrono::steady_clock::now();
          s.results.put(run_challenge(o.challenge));
          if (ctx.progress)
            ctx.say(fmt::format("challenge n_pendulum in {:.2f} s",
                                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
        },
    .write = write_result<challenge_result, write_challenge>,
};

}  // namespace stepbench

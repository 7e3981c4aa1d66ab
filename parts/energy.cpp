// Energy over the long run (/energy): 10^4 periods of our fixed-step methods on the
// pendulum and the orbit, bounded or drifting.
#include "run/energy.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/contains.hpp"
#include "parts/part.hpp"
#include "run/sweep.hpp"
#include "store/energy.hpp"

namespace stepbench {

extern const study_part energy_part{
    .name = "energy",
    .summary = "energy over 10^4 periods: which methods keep it bounded and which drift",
    .describe =
        [](const sweep_options& o) {
          std::vector<std::string> scenes;
          for (const auto& e : o.energy.scenes) {
            std::vector<std::string> params;
            for (const auto& [name, value] : e.params) params.push_back(fmt::format("{}={}", name, value));
            scenes.push_back(fmt::format("{} {} steps a period{}{}", e.problem, e.steps_per_period,
                                         params.empty() ? "" : " ", fmt::join(params, ",")));
          }
          const auto& en = o.energy;
          return fmt::format(
              "energy: periods {}; samples a period {}; series points {}; bounded growth {}; lost {}; methods {}; "
              "scenes {}",
              en.periods, en.samples_per_period, en.series_points, en.bounded_growth, en.lost, list_or_all(en.methods),
              scenes.empty() ? "none" : fmt::format("{}", fmt::join(scenes, "; ")));
        },
    .run =
        [](study& s, const part_context& ctx) {
          // The scenes of this run's problems, with the sweep's methods where it names them.
          energy_options energy = s.options.energy;
          energy.progress = ctx.progress;
          std::erase_if(energy.scenes, [&](const energy_scene& e) { return !contains(ctx.problems, e.problem); });
          if (energy.methods.empty()) energy.methods = s.options.methods;
          if (!energy.scenes.empty()) s.results.put(run_energy_study(energy, s.options.overrides));
        },
    .write = write_result<energy_study, write_energy>,
};

}  // namespace stepbench

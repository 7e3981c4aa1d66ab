// The stability limits and regions of our compiled steps (/stability): of the build, not
// of the selected problems, so every shard of a study computes the same.
#include "run/stability.hpp"

#include "parts/part.hpp"
#include "run/sweep.hpp"
#include "store/stability.hpp"

namespace stepbench {

extern const study_part stability_part{
    .name = "stability",
    .summary = "each integrator's stability limit on the oscillator and decay test equations, and its region",
    .merge = merge_rule::same_in_every_shard,
    .describe = [](const sweep_options&) { return std::string("stability: the default settings"); },
    .run = [](study& s, const part_context&) { s.results.put(compute_stability()); },
    .write = write_result<stability_data, write_stability>,
    .read =
        [](const H5::Group& root, study& s) {
          s.results.put(stability_data{}).limits =
              stability_limit_columns().read(root.openGroup("stability"), "limits");
        },
};

}  // namespace stepbench

// The game programmer's question (/frame_rates): our fixed-step methods at whole frames of
// each rate with n substeps a frame, measured at the frame ends.
#include "run/frame_rates.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "parts/part.hpp"
#include "store/verdict.hpp"

namespace stepbench {

extern const study_part frame_rates_part{
    .name = "frame_rates",
    .summary = "which of our methods is stable and cheapest at 30, 60, 120 and 240 Hz with n substeps a frame",
    .describe =
        [](const sweep_options& o) {
          return fmt::format("frame rates: {} Hz; substeps {}", fmt::join(o.frame_rates.hz, ","),
                             fmt::join(o.frame_rates.substeps, ","));
        },
    .run = [](study& s, const part_context&) { s.results.put(run_frame_rates(s, s.options.frame_rates)); },
    .write = write_frame_rates,
    .read = read_frame_rates,
};

}  // namespace stepbench

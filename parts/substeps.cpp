// Small steps against one implicit step a frame (/substeps): n explicit substeps a frame
// against implicit steps on the stiff problems.
#include "run/substeps.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "parts/part.hpp"
#include "store/substeps.hpp"

namespace stepbench {

extern const study_part substeps_part{
    .name = "substeps",
    .summary = "n explicit substeps a frame against one implicit step, at equal cost and equal error",
    .has_timed_cases = true,
    .describe =
        [](const sweep_options& o) {
          const auto& ss = o.substeps;
          return fmt::format("substeps: problems {}; explicit {}; implicit {}; counts {}; frames {}",
                             list_or_all(ss.problems), list_or_all(ss.explicit_methods),
                             list_or_all(ss.implicit_methods), fmt::join(ss.counts, ","), ss.frames);
        },
    .run = [](study& s, const part_context&) { s.results.put(run_substeps(s, s.options.substeps)); },
    .write =
        [](H5::Group& root, const study& s) {
          write_substeps(root, s.results.get<std::vector<substep_study>>(), s.timed.has_value());
        },
    .read = read_substeps,
};

}  // namespace stepbench

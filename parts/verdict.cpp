// The answer (/verdict): judged from every other part as the study holds it, timings
// included, so it is judged again after stepbench_bench times the rows and after merge
// joins the shards.
#include "judge/verdict.hpp"

#include "parts/part.hpp"
#include "store/verdict.hpp"

namespace stepbench {

extern const study_part verdict_part{
    .name = "verdict",
    .summary = "the fastest of ours against the fastest peer at equal error, the frame-rate answers, the findings",
    .merge = merge_rule::judged_again,
    .judge_again = judge_findings_again,
    .describe = [](const sweep_options&) { return std::string("verdict: targets 1e-2 .. 1e-12"); },
    .judge = [](study& s) { s.results.put(compute_verdict(s)); },
    .write = write_verdict,
    .read = [](const H5::Group& root, study& s) { s.results.put(read_verdict(root)); },
};

}  // namespace stepbench

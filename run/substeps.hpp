#pragma once
// The substeps study's runs (study/substeps.hpp says what it measures).
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// Runs the comparison on the problems of `s` that the options name (their truths are
// already built: the frame ends are the study's sample times).
std::vector<substep_study> run_substeps(const study& s, const substep_options& opts);

}  // namespace stepbench

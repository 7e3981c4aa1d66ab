#pragma once
// The substeps study's verdict: what the implicit step's cost buys in substeps, and what
// they achieve.
#include <vector>

#include "study/study.hpp"

namespace stepbench {

std::vector<substep_verdict> substep_verdicts(const substep_study& s, bool timed);

}  // namespace stepbench

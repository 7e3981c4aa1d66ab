#pragma once
#include <vector>

#include "study/study.hpp"

namespace H5 {
class Group;
}

namespace stepbench {

// /substeps/<problem>: attribute frame_dt (frames = the problem's horizon / frame_dt); methods/<m>/runs (the study's
// row fields plus `substeps` and `extra_damping`); `verdict` (a table of substep_verdict).
void write_substeps(H5::Group& root, const std::vector<substep_study>& studies, bool timed);

}  // namespace stepbench

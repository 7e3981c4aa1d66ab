#pragma once
#include <vector>

#include "store/columns.hpp"
#include "study/study.hpp"

namespace stepbench {

// /substeps/<problem>: attribute frame_dt (frames = the problem's horizon / frame_dt); methods/<m>/runs (the study's
// row fields plus `substeps` and `extra_damping`); `verdict` (a table of substep_verdict).
const column_map<substep_row>& substep_runs_columns();
std::vector<schema::table> substeps_tables();  // in the schema's order (store/schema.cpp)
void write_substeps(H5::Group& root, const std::vector<substep_study>& studies, bool timed);
// /substeps read back (the substeps part's read): each problem's frame and methods' runs,
// each method's declaration the build's where it has the method.
void read_substeps(const H5::Group& root, study& s);

}  // namespace stepbench

#pragma once
#include "store/h5.hpp"
#include "study/stability.hpp"

namespace stepbench {

// Writes /stability under `root` (docs/study-format.md): what run_sweep computed with the
// default settings, in every study file.
void write_stability(H5::Group& root, const stability_data& data);

}  // namespace stepbench

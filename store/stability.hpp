#pragma once
#include "store/columns.hpp"
#include "study/stability.hpp"

namespace stepbench {

// Writes /stability under `root` (docs/study-format.md): what run_sweep computed with the
// default settings, in every study file.
const column_map<stability_limit>& stability_limit_columns();
std::vector<schema::table> stability_tables();  // in the schema's order (store/schema.cpp)
void write_stability(H5::Group& root, const stability_data& data);

}  // namespace stepbench

#pragma once
#include "store/h5.hpp"
#include "study/study.hpp"

namespace stepbench {

// /loop (docs/study-format.md), when the study holds a loop study.
void write_loop(H5::Group& root, const study& s);
std::vector<schema::table> loop_tables();  // in the schema's order (store/schema.cpp)

}  // namespace stepbench

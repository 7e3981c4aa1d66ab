#pragma once
#include "store/h5.hpp"
#include "study/energy.hpp"

namespace stepbench {

// /energy (docs/study-format.md): attributes of the rule, one group per problem with the
// summary table and the error curves.
void write_energy(H5::Group& root, const energy_study& s);
std::vector<schema::table> energy_tables();  // in the schema's order (store/schema.cpp)

}  // namespace stepbench

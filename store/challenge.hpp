#pragma once
#include "store/h5.hpp"
#include "study/challenge.hpp"

namespace stepbench {

// /challenge: attributes (the options, energy_scale), tables `entries`, `verdicts`
// (criterion, verdict) and `small_steps` (docs/study-format.md).
void write_challenge(H5::Group& root, const challenge_result& r);
std::vector<schema::table> challenge_tables();  // in the schema's order (store/schema.cpp)

}  // namespace stepbench

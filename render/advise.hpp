#pragma once
// What `stepbench advise` prints.
#include <cstddef>
#include <string>

#include "judge/advise.hpp"

namespace stepbench {

std::string format_advice(const advice& a, std::size_t runners_up = 5);
std::string format_frame_advice(const frame_advice& f);

}  // namespace stepbench

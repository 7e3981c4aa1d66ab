#pragma once
#include <string>

#include "study/scan.hpp"

namespace stepbench {

std::string format_scan_answer(const scan_answer& a);

}  // namespace stepbench

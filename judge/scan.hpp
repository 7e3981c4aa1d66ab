#pragma once
// A scan's range answer: the cheapest method and substeps stable everywhere and within
// the tolerance wherever there is a truth.
#include "study/scan.hpp"

namespace stepbench {

scan_answer answer_scan(const scan_result& scan, double tol);

}  // namespace stepbench

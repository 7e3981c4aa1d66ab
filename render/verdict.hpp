#pragma once
// The verdict as text: what a study run prints at its end, and two verdicts compared.
#include <string>

#include "study/study.hpp"

namespace stepbench {

// The verdict tables as text: the equal-error table across problems and targets, the
// frame-rate table and the findings (what a study run prints at its end).
std::string format_verdict_text(const study& s);
std::string format_verdict_text(const verdict_tables& v);

std::string format_verdict_agreement(const verdict_agreement& a);

}  // namespace stepbench

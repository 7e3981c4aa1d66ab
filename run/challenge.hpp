#pragma once
// The pendulum challenge's and Small Steps' runs (study/challenge.hpp says what they answer).
#include <string>

#include "study/challenge.hpp"

namespace stepbench {

// Runs both (seconds: about 10 on one core). Progress lines go to `progress` when set.
challenge_result run_challenge(const challenge_options& opts, void (*progress)(const std::string&) = nullptr);

}  // namespace stepbench

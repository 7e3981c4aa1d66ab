#pragma once
// The long-run energy study's runs (study/energy.hpp says what it measures).
#include <map>
#include <string>

#include "study/energy.hpp"

namespace stepbench {

// Runs the study on the scenes the options name, each with the problem's overrides (as
// the sweep takes them). Throws std::invalid_argument for a scene that has no period or
// no energy, or bad options.
energy_study run_energy_study(const energy_options& opts,
                              const std::map<std::string, std::map<std::string, double>>& overrides = {});

}  // namespace stepbench

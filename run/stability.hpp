#pragma once
// The stability limits and regions of our compiled steps (study/stability.hpp says how).
#include <Eigen/Core>
#include <string_view>

#include "study/stability.hpp"

namespace stepbench {

stability_data compute_stability(const stability_settings& settings = {});

// The amplification matrix of one step of `integrator` (a name in all_integrators) on
// `test` at y: the map [x; v] -> [x; v] of one step of dt = y with omega = lambda = 1.
// Throws std::invalid_argument for an unknown name.
Eigen::Matrix2d amplification_matrix(std::string_view integrator, stability_test test, double y);
// max |eigenvalue| of a 2x2 matrix, from its trace and determinant.
double spectral_radius(const Eigen::Matrix2d& m);

}  // namespace stepbench

#pragma once
// Friction on an incline (the lecture's forces). Not time-stepped: the lecture's
// two worked examples are closed-form, so this is a small helper checked by the tests.
#include <cmath>

namespace stepbench::incline {

// Normal force on an incline of angle theta: |F_n| = m g cos(theta).
inline double normal_force(double mass, double g, double theta) { return mass * g * std::cos(theta); }

// Acceleration down the slope of a sliding block with kinetic friction mu_k:
// a = g sin(theta) - mu_k g cos(theta). Negative means kinetic friction would stop it.
inline double sliding_acceleration(double g, double theta, double mu_k) {
  return g * std::sin(theta) - mu_k * g * std::cos(theta);
}

// Tilt at which a block at rest starts to slide: m g sin(theta) = mu_s m g cos(theta),
// so theta = atan(mu_s).
inline double sliding_angle(double mu_s) { return std::atan(mu_s); }

}  // namespace stepbench::incline

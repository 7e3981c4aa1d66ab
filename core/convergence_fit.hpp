#pragma once
// Observed order of convergence from an error-versus-dt ladder.
//
// The error of an order-p method behaves as C dt^p only in the asymptotic range: below
// it (large dt) higher-order terms or instability dominate; above it (small dt)
// round-off does. The fit therefore:
//  1. drops diverged levels and levels whose error is not clearly above round-off
//     noise (100 times its typical size eps scale sqrt(n), n = steps: rounding errors
//     of a stable method accumulate like a random walk) or not clearly below the
//     motion's size (10 % of its amplitude);
//  2. starting from the finest remaining pair, extends towards larger dt while each
//     local slope log(e_k / e_{k+1}) / log(dt_k / dt_{k+1}) stays within 0.1 of the
//     median slope of the levels already taken (if that leaves fewer than three levels,
//     the window ending one level coarser is tried, and so on);
//  3. fits log e = p log dt + c by least squares over those levels (at least 3).
// When every level's error is within the worst-case round-off bound 8 eps n scale and
// does not fall with dt, the method is exact for the problem (RK4 on constant
// acceleration): no slope is fitted and the order is NaN.
#include <limits>
#include <string>
#include <vector>

namespace stepbench {

struct fit_input {
  std::vector<double> dt;     // decreasing
  std::vector<double> error;  // the fitted metric at each level
  std::vector<long> steps;
  std::vector<bool> incomplete;  // the row did not complete (diverged, failed or skipped): not fitted
  double scale = 1.0;            // size of the motion in the metric's unit
};

struct fit_result {
  enum class status { fitted, exact, insufficient };
  status state = status::insufficient;
  double order = std::numeric_limits<double>::quiet_NaN();  // NaN unless fitted
  double intercept = 0.0;
  double residual = 0.0;    // RMS of the log10 residuals
  std::vector<int> levels;  // ladder indices used by the fit
  std::string note;         // why, when not fitted
};

inline const char* to_string(fit_result::status s) {
  constexpr const char* names[] = {"fitted", "exact", "insufficient"};
  return names[static_cast<int>(s)];
}

// Worst-case round-off bound for n steps on a motion of size `scale`: 8 eps n scale.
double roundoff_bound(long steps, double scale);
// Typical accumulated round-off for n steps: eps scale sqrt(n).
double roundoff_noise(long steps, double scale);

fit_result fit_order(const fit_input& in);

// Whether a method achieves the order it declares: 1 when the fitted order is within
// declared_order_slack of it, 0 when not (GSL's rk2 declares 2 and achieves 3; Boost's
// velocity_verlet declares 1 and achieves 2), -1 when it cannot be said (no declared
// order, or no fitted one). Recorded in the study file; every reader shows this value.
inline constexpr double declared_order_slack = 0.5;
int declared_order_holds(double declared, const fit_result& fit);

}  // namespace stepbench

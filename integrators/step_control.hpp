#pragma once
// Step-size control shared by the adaptive methods (not a method itself), after Hairer,
// Norsett & Wanner, Solving ODEs I, 2nd ed. (HNW I), sec. II.4:
//  - the error of a step is measured in the RMS norm of the error estimate e scaled per
//    component by sc_i = atol + rtol max(|y0_i|, |y1_i|) (eq. 4.11), over y = [x; v],
//    with rtol = atol = the method's tolerance (as for the library peers);
//  - the first step is Hairer's starting-step algorithm (HNW I, sec. II.4, "Starting
//    step size"), two force evaluations;
//  - the next step is h (1 / err)^(1 / (q + 1)) with safety factor 0.9, within [0.2, 10]
//    times h, q the order of the error estimate; with `beta` > 0 the PI controller of
//    HNW I sec. IV.2 / dopri5.f (Gustafsson's stabilisation: (err_old)^beta in the
//    denominator), and never larger than h right after a rejected step.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "core/concepts.hpp"

namespace stepbench {

// sqrt(1/n sum_i (e_i / sc_i)^2) over the 2 dim components of [x; v].
template <class EX, class EV, class Vec>
inline double scaled_rms(const EX& ex, const EV& ev, const Vec& x0, const Vec& v0, const Vec& x1, const Vec& v1,
                         double tol) {
  const auto sx = tol + tol * x0.cwiseAbs().cwiseMax(x1.cwiseAbs()).array();
  const auto sv = tol + tol * v0.cwiseAbs().cwiseMax(v1.cwiseAbs()).array();
  const double sum = (ex.array() / sx).square().sum() + (ev.array() / sv).square().sum();
  return std::sqrt(sum / static_cast<double>(2 * x0.size()));
}

// Hairer's starting step for a method of order p: with d0 = ||y0||, d1 = ||f(y0)||
// (scaled norms), h0 = 0.01 d0 / d1; an explicit Euler step of h0 gives
// d2 = ||f(y1) - f(y0)|| / h0; h1 = (0.01 / max(d1, d2))^(1/(p+1)); h = min(100 h0, h1).
// `f0` is F at the start (computed by the caller); `xs, vs, fs` are workspace.
template <class Sys, class Vec>
inline double starting_step(const Sys& sys, double t, const Vec& x0, const Vec& v0, const Vec& f0, int p, double tol,
                            double horizon, Vec& xs, Vec& vs, Vec& fs) {
  const double im = inverse_mass(sys);
  const auto norm = [&](const auto& ax, const auto& av) {
    const auto sx = tol + tol * x0.cwiseAbs().array();
    const auto sv = tol + tol * v0.cwiseAbs().array();
    return std::sqrt(((ax.array() / sx).square().sum() + (av.array() / sv).square().sum()) /
                     static_cast<double>(2 * x0.size()));
  };
  const double d0 = norm(x0, v0), d1 = norm(v0, (im * f0).eval());
  double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0 = std::min(h0, horizon);
  xs = x0 + h0 * v0;
  vs = v0 + (h0 * im) * f0;
  sys.force(t + h0, xs, vs, fs);
  const double d2 = norm((vs - v0).eval(), (im * (fs - f0)).eval()) / h0;
  const double h1 =
      std::max(d1, d2) <= 1e-15 ? std::max(1e-6, h0 * 1e-3) : std::pow(0.01 / std::max(d1, d2), 1.0 / (p + 1));
  return std::min({100.0 * h0, h1, horizon});
}

// The step-size controller: returns the next step to try after a step of h with
// scaled error `err`; `accepted` is err <= 1.
struct step_controller {
  int error_order = 1;  // q: the order of the error estimate's leading term is q + 1
  double beta = 0.0;    // PI stabilisation (0: plain controller)
  double safety = 0.9, min_factor = 0.2, max_factor = 10.0;
  double err_old = 1e-4;
  bool rejected_last = false;

  double next(double h, double err) {
    const double expo = 1.0 / (error_order + 1) - 0.75 * beta;
    double factor;
    if (err <= 1.0) {
      factor = err == 0.0 ? max_factor : safety * std::pow(err, -expo) * std::pow(err_old, beta);
      factor = std::clamp(factor, min_factor, rejected_last ? 1.0 : max_factor);
      err_old = std::max(err, 1e-4);
      rejected_last = false;
    } else {
      factor = std::isfinite(err) ? std::clamp(safety * std::pow(err, -1.0 / (error_order + 1)), min_factor, 1.0)
                                  : min_factor;
      rejected_last = true;
    }
    return h * factor;
  }
};

}  // namespace stepbench

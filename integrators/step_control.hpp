#pragma once
// Step-size control shared by the adaptive methods (not a method itself), after Hairer,
// Norsett & Wanner, Solving ODEs I, 2nd ed. (HNW I), sec. II.4:
//  - the error of a step is measured in the RMS norm of the error estimate e scaled per
//    component by sc_i = atol + rtol max(|y0_i|, |y1_i|) (eq. 4.11), over y = [x; v],
//    with rtol = atol = the method's tolerance (as for the library peers);
//  - the first step is Hairer's starting-step algorithm (HNW I, sec. II.4, "Starting
//    step size"), two force evaluations;
//  - the next step from step_controller below (dopri5.f's and dop853.f's).
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
// From the state s at t; `xs, vs, fs` are workspace.
template <class Sys, class Vec>
inline double starting_step(const Sys& sys, double t, step_state<Vec>& s, int p, double tol, double horizon, Vec& xs,
                            Vec& vs, Vec& fs) {
  const Vec &x0 = s.x, &v0 = s.v, &f0 = current_force(sys, t, s);
  const double im = inverse_mass(sys);
  // Scaled by y0 alone: max(|y0|, |y0|) = |y0|.
  const auto norm = [&](const auto& ax, const auto& av) { return scaled_rms(ax, av, x0, v0, x0, v0, tol); };
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

// The step-size controller, the one every adaptive method of ours composes with its
// error-estimating step (as Boost.Odeint's controlled_runge_kutta composes an error
// stepper with a step adjuster): Hairer's (HNW I, sec. II.4, eq. 4.13, and sec. IV.2;
// dopri5.f, dop853.f). After a step of h with scaled error err (accepted when err <= 1),
// q the order of the error estimate:
//   accepted:  h_new = h min(max_factor, max(min_factor, safety err^-(1/(q+1) - 0.75 beta) err_old^beta)),
//              no larger than h right after a rejection; err_old = max(err, 1e-4)
//   rejected:  h_new = h max(min_factor, safety err^-(1/(q+1)))
// beta > 0 is Gustafsson's PI stabilisation on accepted steps (dopri5.f: 0.04); beta = 0
// the plain controller (dop853.f). A NaN or infinite error (a step that blew up) is a
// rejection by min_factor.
// One formula, computed in one of two roundings: `quotient` as Hairer's Fortran codes
// compute it, h / clamp(err^e / safety, ...) (dop853), or `product` as the formula reads
// (rk45 and adaptive_euler). The two differ in the last bit of h only; each method keeps
// the rounding it has always had, so that the study's tables stay bit-identical (an ulp
// of h moves a chaotic bounce sequence, tests/test_accuracy_fixture.cpp's rule).
struct step_controller {
  enum class rounding { product, quotient };
  int error_order = 1;
  double beta = 0.0;
  double safety = 0.9, min_factor = 0.2, max_factor = 10.0;
  rounding form = rounding::product;
  double err_old = 1e-4;
  bool rejected_last = false;

  // err^e. For e = 1/8 (dop853's), three square roots: the next step's coefficients wait
  // for it, and pow() would cost a fifth of a DOP853 step on one coordinate.
  static double root(double err, double e) {
    if (e == 0.125) return std::sqrt(std::sqrt(std::sqrt(err)));
    return std::pow(err, e);
  }

  double next(double h, double err) {
    const double e = 1.0 / (error_order + 1);
    const bool accepted = err <= 1.0;
    double h_new;
    if (form == rounding::product) {
      double factor;
      if (accepted) {
        factor = err == 0.0 ? max_factor : safety * std::pow(err, -(e - 0.75 * beta)) * std::pow(err_old, beta);
        factor = std::clamp(factor, min_factor, rejected_last ? 1.0 : max_factor);
      } else {
        factor = std::isfinite(err) ? std::clamp(safety * std::pow(err, -e), min_factor, 1.0) : min_factor;
      }
      h_new = h * factor;
    } else {
      const double fac_min = 1.0 / max_factor, fac_max = 1.0 / min_factor;
      if (accepted) {
        const double fac = beta == 0.0 ? root(err, e) : root(err, e - 0.75 * beta) / std::pow(err_old, beta);
        h_new = h / std::clamp(fac / safety, fac_min, fac_max);
        if (rejected_last) h_new = std::min(h_new, h);
      } else {
        h_new = h / (std::isfinite(err) ? std::min(fac_max, root(err, e) / safety) : fac_max);
      }
    }
    if (accepted) err_old = std::max(err, 1e-4);
    rejected_last = !accepted;
    return h_new;
  }

  // One attempt of an error-estimating step: `err` is the scaled error of the candidate;
  // on acceptance `commit()` makes the candidate the state.
  template <class Commit>
  step_attempt attempt(double h, double err, Commit&& commit) {
    const double h_next = next(h, err);
    if (!(err <= 1.0)) return {false, 0.0, h_next};
    commit();
    return {true, h, h_next};
  }
};

}  // namespace stepbench

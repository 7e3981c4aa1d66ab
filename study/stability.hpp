#pragma once
// Linear stability of our integrators, measured from their compiled steps (the same
// instantiations the study runs), not from a copy of the step code:
//
//  - limits: the largest stable y = omega dt on the undamped oscillator x'' = -omega^2 x,
//    and the largest stable y = lambda dt on pure decay, found two ways:
//      (a) `theory`: the amplification matrix M(y) of one step (its columns: one step
//          from [x; v] = [1; 0] and [0; 1]); the limit is the root of
//          g(y) = rho(M(y)) - 1 - rho_tol, rho the spectral radius;
//      (b) `measured`: bisection on long runs of the stepper (N steps, unstable when the
//          envelope of the motion grows; stability_settings says how);
//  - regions: |R(z)| on a grid of the complex plane z = dt lambda, from one step of a
//    damper with a complex rate.
//
// An adaptive method is measured by the step it takes when every attempt is accepted:
// it is constructed with a tolerance so large (`always_accept_tolerance`) that the error
// test always passes, so its step is rk45's Dormand-Prince step and adaptive_euler's two
// half steps of explicit Euler.
//
// Computed by the stability part (parts/stability.cpp, run/stability.cpp), written to the study file as
// /stability (docs/study-format.md), and printed by `stepbench stability`.
#include <string>
#include <string_view>
#include <vector>

namespace stepbench {

// The two linear test problems (defined in run/stability.cpp, not study problems):
//   oscillator  x'' = -omega^2 x, as the force F = -m omega^2 x; y = omega dt;
//   decay       a pure damper F = -m lambda v, so v' = -lambda v and x only integrates v
//               (the form a damper takes in a game; the velocity equation is the one that
//               must stay bounded); y = lambda dt.
enum class stability_test { oscillator, decay };
std::string_view to_string(stability_test t);

struct stability_settings {
  // (a) The scan: y on a log grid, per_decade points a decade from y_min to y_max, then
  // y_unconditional. A method whose rho - 1 is above rho_tol already at y_min, by more
  // than clear_factor x rho_tol, is unstable for every dt; one stable on the whole scan
  // is unconditionally stable. Otherwise the first unstable grid point and the one
  // before it bracket the limit, bisected to root_rtol.
  double y_min = 1e-3;
  double y_max = 1e4;
  double y_unconditional = 1e6;
  int per_decade = 50;
  // Round-off allowance on rho: a symplectic method has rho = 1 to rounding inside its
  // interval (complex eigenvalues of modulus sqrt(det M) = 1); the largest rho - 1 seen
  // at a stable y is one ulp of 1 (2.2e-16). Explicit midpoint's rho - 1 = y^4 / 8 is
  // 1.25e-13 at y = 1e-3, so the allowance must be well below that.
  double rho_tol = 5e-15;
  double clear_factor = 10.0;
  double root_rtol = 1e-12;
  // (b) Long runs: run_steps steps of the stepper from (x, v) = (1, 0) on the oscillator,
  // (0, 1) on decay, watching the size of the motion: |[x; v]| on the oscillator
  // (omega = 1, so the amplitude), |v| on decay. A run grows (the method is unstable at
  // that y) when the largest size over its second half exceeds envelope_growth x the
  // largest over its first half; it stops early, grown, when the size passes
  // blowup_factor x its start or is not finite, and bounded when the size falls below
  // decay_floor x its start (every mode has decayed; the rest of the run would be
  // subnormal numbers, whose arithmetic is slow). The envelope is compared, not the size
  // with its start: a bounded motion can sweep a thin ellipse (semi-implicit Euler near
  // omega dt = 2: axes in the ratio sqrt((2 + y) / (2 - y))) and an unstable one can grow
  // slowly (rk45 just past its oscillator limit: |R| - 1 = 1.4e-6 at y = 1.0, so
  // 100-fold growth would take 3e6 steps). The bracket: y from run_y_start up (or down)
  // by factors 10^(1 / run_per_decade) to the first change of verdict; then bisection to
  // run_rtol.
  long run_steps = 10000;
  double envelope_growth = 1.01;
  double blowup_factor = 1e6;
  double decay_floor = 1e-150;
  double run_y_start = 0.1;
  int run_per_decade = 10;
  double run_rtol = 1e-6;
  // A method unstable for every dt must grow in a run at confirm_y (explicit midpoint
  // grows by y^4 / 8 a step: 1.25e-5 at y = 0.1, a 6 % larger envelope over 10^4 steps;
  // at y = 0.01 it would be 1.25e-9 a step, not measurable in a short run); an
  // unconditionally stable one must stay bounded at y_max and at y_unconditional.
  double confirm_y = 0.1;
  // (a) and (b) agree when |measured / theory - 1| <= agreement.
  double agreement = 0.01;
  // The grid of the regions: re_count x im_count points, both axes through 0.
  double re_min = -6.0, re_max = 2.0;
  double im_min = -5.0, im_max = 5.0;
  int re_count = 201, im_count = 201;
};

// The tolerance an adaptive method is constructed with here: its scaled error is
// |e| / (tol (1 + |y|)), at most 1 for any error estimate below 1e100.
inline constexpr double always_accept_tolerance = 1e100;

struct stability_limit {
  std::string integrator;
  stability_test test = stability_test::oscillator;
  double theory = 0.0;    // (a); NaN when it does not apply (a flag is set)
  double measured = 0.0;  // (b); NaN when it does not apply
  bool unstable_for_all_dt = false;
  bool unconditionally_stable = false;
  // The long runs agree with (a): a finite limit within `agreement`, growth for a method
  // unstable for every dt, boundedness for an unconditionally stable one.
  bool run_confirms = false;
  // The smallest y at which the compiled step failed (an implicit method's Newton
  // iteration did not converge), in the scan or the runs; NaN when it never did. Such a
  // y is neither stable nor unstable: a method whose step fails somewhere gets neither
  // flag unless the runs and the scan decide without it.
  double step_failed_at = 0.0;
  std::string note;                                                  // what the scan and the long runs found, in words
  double rel_difference() const { return measured / theory - 1.0; }  // NaN unless both are finite
};

// |R(z)| on the grid, per method: abs_r[k][i * re.size() + j] = |R(re[j] + i im[i])| for
// integrator k; NaN where the step does not exist (a pole of an implicit method's R).
struct stability_regions {
  std::vector<double> re, im;
  std::vector<std::string> integrators;
  std::vector<std::vector<double>> abs_r;
  const std::vector<double>& of(std::string_view integrator) const;  // throws std::out_of_range
};

struct stability_data {
  stability_settings settings;
  std::vector<stability_limit> limits;  // every integrator of all_integrators, oscillator then decay
  stability_regions regions;
  double limits_seconds = 0.0, regions_seconds = 0.0;
};

}  // namespace stepbench

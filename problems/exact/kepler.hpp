#pragma once
// Exact Kepler motion: a body around a fixed mass, F = -gm m r / |r|^3 in 2-D, started at
// periapsis as in the DETEST orbit problems (Hull, Enright, Fellen and Sedgwick, "Comparing
// numerical methods for ordinary differential equations", SIAM J. Numer. Anal. 9 (1972),
// class D, there with gm = a = 1 and e = 0.1 ... 0.9):
//   r0 = (a (1 - e), 0),   v0 = (0, sqrt(gm (1 + e) / (a (1 - e)))).
//
// Closed form (e.g. Danby, "Fundamentals of Celestial Mechanics", ch. 6). Mean motion
// n = sqrt(gm / a^3), period T = 2 pi / n, mean anomaly M = n t. The eccentric anomaly E
// solves Kepler's equation E - e sin E = M, and
//   x = a (cos E - e),  y = b sin E,  b = a sqrt(1 - e^2),
//   dE/dt = n / (1 - e cos E)  (differentiate Kepler's equation),
//   vx = -a sin E dE/dt,  vy = b cos E dE/dt.
// Constants: specific energy -gm / (2 a), specific angular momentum sqrt(gm a (1 - e^2)).
//
// Written without cancellation near periapsis, where e -> 1 makes the orbit's scale
// a (1 - e) tiny compared with a:
//   1 - e cos E = (1 - e) + 2 e sin^2(E/2),  cos E - e = (1 - e) - 2 sin^2(E/2),
//   E - e sin E = (1 - e) E + e (E - sin E), with E - sin E from its Taylor series for |E| < 2,
//   1 - e^2 = (1 - e)(1 + e).
// And without overflow: a^3 is never formed (n = sqrt(gm / a) / a, T = 2 pi a sqrt(a / gm)).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace stepbench::exact {

// E - sin E, relatively accurate for every E. For small |E| the difference would cancel
// (E - sin E ~ E^3 / 6), so below |E| = 2 it is summed as a series, nested:
//   E - sin E = E^3/3! - E^5/5! + ... = (E^3 / 6) (1 - E^2/(4*5) (1 - E^2/(6*7) (1 - ...))).
// Eleven factors reach E^25 / 25!; the first term left out, E^27 / 27!, is below 2e-20 of
// the sum at |E| = 2, and the largest term there (E^3 / 6) is only 1.2 times the sum.
inline double e_minus_sin(double ecc_anomaly) {
  const double E = ecc_anomaly;
  if (!(std::abs(E) < 2.0)) return E - std::sin(E);
  const double e2 = E * E;
  double s = 1.0;
  for (double d : {24.0 * 25.0, 22.0 * 23.0, 20.0 * 21.0, 18.0 * 19.0, 16.0 * 17.0, 14.0 * 15.0, 12.0 * 13.0,
                   10.0 * 11.0, 8.0 * 9.0, 6.0 * 7.0, 4.0 * 5.0})
    s = 1.0 - e2 / d * s;
  return E * e2 / 6.0 * s;
}

struct kepler_root {
  double eccentric_anomaly;  // in [-pi, pi], same sign as the reduced mean anomaly
  int iterations;            // Halley steps taken (0 when M reduces to 0)
};

// Largest number of Halley steps solve_kepler takes. Measured over e in {0, 1e-10, 0.01,
// 0.2, 0.5, 0.8, 0.9, 0.97, 0.99, 0.995, 0.999, 1 - 1e-4, ..., 1 - 1e-15} against 300000 mean
// anomalies each (uniform in [-4, 4] and log-uniform from 1e-300 to 3): no case needs more
// than 4 (and the bisection safeguard is never taken); typically 1 for tiny M, 3 to 4 for M
// near pi. tests/test_exact_motion.cpp re-checks the bound on 20000 anomalies per e.
inline constexpr int kepler_max_iterations = 4;

// Solves E - e sin E = M for 0 <= e < 1, to round-off: E is within about an ulp of the
// root (|dE| <= 1.1 eps |E| measured in that scan; the tests assert 1.5 eps) and the residual
// of the reduced equation below 2.6 eps (the tests assert 4 eps).
// - M is reduced to [-pi, pi] by std::remainder (exact); E(-M) = -E(M), so the work is done
//   on m = |M| in [0, pi]. With f(E) = E - e sin E - m, increasing, f(m) = -e sin m <= 0 and
//   f(m + e) >= 0, f(pi) >= 0, f(m / (1 - e)) >= 0 (as E - sin E >= 0), so the root lies in
//   [m, min(m + e, pi, m / (1 - e))]. That bracket is kept and shrunk by each residual's sign.
// - Start: Danby's E0 = m + 0.85 e (Danby, "Fundamentals of Celestial Mechanics", 2nd ed.,
//   ch. 6; sign(sin M) = +1 for m in (0, pi)), or, if smaller, cbrt(6 m / e), the root of
//   the cubic model e E^3 / 6 = m; clamped to the bracket. The two extra bounds matter for
//   tiny m: there the root is about m / (1 - e) (or cbrt(6 m / e) when e -> 1), and Halley's
//   step from Danby's E0 ~ 0.85 e would leave an absolute error of eps * 0.85 e, far above
//   the root itself.
// - Halley steps dE = -f / (f' - f f'' / (2 f')), f' = (1 - e) + 2 e sin^2(E/2) (= 1 - e cos E
//   without cancellation), f'' = e sin E. The residual is computed so that E keeps its
//   relative accuracy even when e -> 1 and m -> 0 (see below). A step that would leave the
//   bracket (widened by 4 ulps for the rounding of its ends) is replaced by bisection: a
//   safeguard the scan never triggers.
// - Stops after the step whose correction is below 4 ulps of E (|dE| <= 4 eps |E|): Halley
//   converges cubically, so that step left an error far below an ulp. The loop is capped at
//   50 steps; kepler_max_iterations is what it takes in practice.
inline kepler_root solve_kepler(double mean_anomaly, double e) {
  constexpr double pi = std::numbers::pi, eps = std::numeric_limits<double>::epsilon();
  const double M = std::remainder(mean_anomaly, 2.0 * pi);
  const double m = std::abs(M);
  if (m == 0.0 || e == 0.0) return {M, 0};
  const double one_minus_e = 1.0 - e;
  double lo = m, hi = std::min({m + e, pi, m / one_minus_e});
  double E = std::clamp(std::min(m + 0.85 * e, std::cbrt(6.0 * m / e)), lo, hi);
  int it = 0;
  while (it < 50) {
    ++it;
    const double sin_e = std::sin(E), half = std::sin(0.5 * E);
    // Residual f = E - e sin E - m. Where E <= 2 m, directly as (E - m) - e sin E: E - m is
    // exact (Sterbenz, E >= m) and only e sin E <= E / 2 is rounded. Otherwise (e sin E is
    // most of E: e -> 1, E small) in the split form (1 - e) E - m + e (E - sin E), which
    // does not cancel. (Near the root m = E - e sin E >= E - 1, so E > 2 m only below E = 2,
    // where e_minus_sin uses its series.)
    const double f = E <= 2.0 * m ? (E - m) - e * sin_e : (one_minus_e * E - m) + e * e_minus_sin(E);
    if (f > 0.0) {
      hi = E;
    } else if (f < 0.0) {
      lo = E;
    } else {
      break;
    }
    const double fp = one_minus_e + 2.0 * e * half * half;
    const double fpp = e * sin_e;
    double next = E - f / (fp - 0.5 * f * fpp / fp);
    const double slack = 4.0 * eps * hi;  // the bracket's ends carry rounding errors of their own
    if (!(next >= lo - slack && next <= hi + slack)) next = 0.5 * (lo + hi);
    const double step = next - E;
    E = next;
    if (std::abs(step) <= 4.0 * eps * E) break;
  }
  return {std::copysign(E, M), it};
}

// Position and velocity in the orbital plane; the fixed mass is at the origin.
struct kepler_state {
  double x, y, vx, vy;
};

struct kepler_orbit {
  double gm = 1.0;  // gravitational parameter G M
  double a = 1.0;   // semi-major axis
  double e = 0.5;   // eccentricity, 0 <= e < 1

  double mean_motion() const { return std::sqrt(gm / a) / a; }
  double period() const { return 2.0 * std::numbers::pi * a * std::sqrt(a / gm); }
  double semi_minor_axis() const { return a * std::sqrt((1.0 - e) * (1.0 + e)); }

  kepler_state initial() const {
    return {a * (1.0 - e), 0.0, 0.0, std::sqrt(gm / a) * std::sqrt((1.0 + e) / (1.0 - e))};
  }

  // State at time t (any sign). The mean anomaly comes from the fraction of the period,
  // M = 2 pi (t/T - nearest integer): t = k T lands on M = 0 up to the rounding of t/T, and
  // the subtraction of the integer is exact.
  kepler_state at(double t) const {
    const double M = 2.0 * std::numbers::pi * std::remainder(t / period(), 1.0);
    const double E = solve_kepler(M, e).eccentric_anomaly;
    const double s = std::sin(E), c = std::cos(E), half = std::sin(0.5 * E);
    const double one_minus_ecos = (1.0 - e) + 2.0 * e * half * half;  // r / a
    const double b = semi_minor_axis();
    const double edot = mean_motion() / one_minus_ecos;
    return {a * ((1.0 - e) - 2.0 * half * half), b * s, -a * s * edot, b * c * edot};
  }
};

}  // namespace stepbench::exact

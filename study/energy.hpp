#pragma once
// Long-run energy: every fixed-step integrator of ours on the pendulum and on the Kepler
// orbit for 10^4 periods at a stated dt (a whole number of steps a period), the energy
// error sampled 32 times a period, and what it does over the run:
//   - the largest relative error |E - E0| / |E0| over the samples;
//   - the secular drift per period: the least-squares slope, against the period count,
//     of each period's peak error (the sample of largest |E - E0| in the period, signed).
//     The peak, not the error at a fixed phase: a method's period differs from the exact
//     one, so a fixed phase of the exact period drifts along the method's oscillation, and
//     a bounded error sampled there shows a slope that depends on the run's length;
//     32 samples a period resolve the peak of an error that oscillates twice a period;
//   - bounded or drifting: bounded when the largest error over the last tenth of the
//     run is at most twice the largest over the first tenth and the error stays below
//     1/2 (a method that has dissipated or doubled the energy has not kept it, however
//     flat its error is by then); drifting otherwise, with its sign (the mean error over
//     the last tenth: > 0 gains energy, < 0 loses it);
//   - on kepler, the same for the angular momentum about the fixed mass.
// A symplectic method keeps a modified energy (Hairer, Lubich & Wanner, Geometric
// Numerical Integration, 2nd ed., ch. IX): its error oscillates without drift; explicit
// Euler and the explicit midpoint rule gain energy on oscillators, RK4 loses it.
// Runs through the registry's drive loops, like every study row.
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/method.hpp"
#include "core/parameter.hpp"

namespace stepbench {

struct energy_scene {
  std::string problem;
  int steps_per_period = 64;
  std::map<std::string, double> params;  // the scene's own defaults; the user's --set wins
  // The time unit of the drift: the problem's period where it has one (pendulum, kepler);
  // else this (`stepbench energy --period`); else the problem's horizon.
  double period = std::numeric_limits<double>::quiet_NaN();
};

struct energy_options {
  // Pendulum: its default 120-degree swing, T = 2.755 s, 64 steps a period (dt = 0.043 s).
  // Kepler: e = 0.5 (the sweep's default 0.9 passes periapsis in ~15 steps of a
  // 1000-step orbit, where semi-implicit Euler's bounded energy error reaches 93% and
  // says nothing about drift), 1024 steps an orbit (dt = 6.1 ms).
  std::vector<energy_scene> scenes{{"pendulum", 64, {}}, {"kepler", 1024, {{"eccentricity", 0.5}}}};
  double periods = 1e4;
  int samples_per_period = 32;       // must divide steps_per_period
  int series_points = 160;           // points of the stored error curve (log-spaced in time)
  double bounded_growth = 2.0;       // last tenth's largest error over the first tenth's, at most
  double lost = 0.5;                 // an error this large (relative) is not bounded
  std::vector<std::string> methods;  // empty: every fixed-step integrator of ours
  bool progress = false;
};

struct energy_run {
  method_info info;
  double dt = 0.0;
  long steps = 0;
  long force_evals = 0;
  bool completed = false;         // ran to the end with finite states
  std::string note;               // why not
  double max_rel_err = 0.0;       // max |E - E0| / |E0| over the samples
  double final_rel_err = 0.0;     // (E - E0) / |E0| at the end, signed
  double drift_per_period = 0.0;  // slope of each period's peak (E - E0) / |E0|, per period
  double first_tenth_max = 0.0, last_tenth_max = 0.0, last_tenth_mean = 0.0;
  std::string verdict;                   // "bounded" or "drifting" ("" when not completed)
  int drift_sign = 0;                    // +1 gains, -1 loses (drifting only)
  double angmom_max_rel_err = 0.0;       // NaN without angular momentum
  double angmom_drift_per_period = 0.0;  // NaN without
  double seconds = 0.0;
  std::vector<double> series_t;    // the error curve: at each time, the signed error of largest
  std::vector<double> series_err;  // magnitude since the previous point (an envelope for a log axis)
};

struct energy_problem {
  std::string problem;
  std::vector<param_value> params;  // the scene's, as declared
  double period = 0.0, dt = 0.0, horizon = 0.0, e0 = 0.0, l0 = 0.0;
  int steps_per_period = 0;
  std::vector<energy_run> runs;
};

struct energy_study {
  energy_options options;
  std::vector<energy_problem> problems;
  double wall_seconds = 0.0;
};

}  // namespace stepbench

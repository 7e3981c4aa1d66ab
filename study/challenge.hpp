#pragma once
// The pendulum challenge, answered with measured numbers, and the Small Steps experiment.
//
// Mueller's "pendulum challenge" (Ten Minute Physics, 2022): XPBD steps a 3-link
// pendulum (1 kg, 0.3 m a link, g = 10 m/s^2, released with every link horizontal) at
// a 60 Hz frame with 50 substeps, and invites anyone "to beat our method in terms of
// simplicity, speed, stability or accuracy". Here, on problems/n_pendulum.hpp with its
// defaults: xpbd with 50 substeps a frame against rk4, rk8 (DOP853's step at a fixed
// dt), dop853 (adaptive), implicit_midpoint and semi_implicit_euler in generalized
// coordinates, each given the most whole steps a frame whose measured time per frame is
// at most xpbd's (at least one); dop853, the tightest of the tolerances 1e-1, 1e-2, ...
// whose measured time per frame is at most xpbd's. Per method: the bobs' largest position error over `horizon` against
// the references, the energy drift over `energy_horizon`, the link-length error, and the time per frame. A verdict a
// criterion the challenge names, computed here:
//   accuracy: the smallest error at xpbd's time per frame;
//   stability: every method's energy drift over energy_horizon (bounded or not);
//   speed: the time per frame each needs for xpbd's error, interpolated log-log between
//          the two measured step counts that bracket it (on the measured curve).
//
// The Small Steps experiment (Macklin et al., SCA 2019, figs. 4-6): on n_pendulum and
// spring_chain, the position error and the constraint (link length) error at t = 1 s,
// for n substeps of one constraint pass against one step of n passes (lambda
// accumulated), against n semi-implicit Euler substeps and one implicit Euler step; the
// counted cost (force evaluations or constraint passes a frame) and the measured time
// a frame for each.
#include <limits>
#include <string>
#include <vector>

namespace stepbench {

struct challenge_options {
  double hz = 60.0;
  int xpbd_substeps = 50;
  double horizon = 2.0;            // s; GSL rk8pd and ARKODE erk8 agree to 4e-14 on the bobs here
  double energy_horizon = 1000.0;  // s
  std::vector<std::string> competitors{"rk4", "rk8", "dop853", "implicit_midpoint", "semi_implicit_euler"};
  std::vector<int> small_steps_counts{1, 2, 4, 8, 16, 32, 64};
  double small_steps_time = 1.0;  // s
};

struct challenge_entry {
  std::string method;
  int steps_per_frame = 0;  // an adaptive method's: its accepted steps a frame, rounded
  double tolerance = std::numeric_limits<double>::quiet_NaN();  // an adaptive method's; NaN otherwise
  double ns_per_frame = 0.0;    // measured: the median of repeated whole runs over `horizon`
  double err_pos_max = 0.0;     // bobs [m] over horizon
  double energy_drift = 0.0;    // (E(energy_horizon) - E0) / |E0 scale|, signed
  double energy_err_max = 0.0;  // max |E - E0| / scale over energy_horizon (sampled each second)
  double link_err_max = 0.0;    // max over frames of |link length - l| / l (0 in generalized coordinates)
  bool stable = true;           // finite, and the energy error stayed under the scale
  bool over_xpbd_time = false;  // even its cheapest setting took longer a frame than xpbd (not "most accurate")
  double ns_per_frame_at_xpbd_error = 0.0;  // interpolated; NaN when no measured count reaches it
  std::string note;
};

struct small_steps_row {
  std::string problem;
  std::string design;           // xpbd_substeps, xpbd_iterations, semi_implicit_euler_substeps, implicit_euler
  int n = 0;                    // substeps or passes a frame (1 for implicit_euler)
  double err_pos = 0.0;         // [m] at small_steps_time, on the observed positions
  double link_err = 0.0;        // max_j |C_j(x) - C_j(x_true)| / L_j at small_steps_time
  double work_per_frame = 0.0;  // force evaluations or constraint passes
  double ns_per_frame = 0.0;
  bool diverged = false;
};

struct challenge_result {
  challenge_options options;
  double energy_scale = 0.0;                  // |E| of the chain hanging at rest: m g l N(N+1)/2
  std::vector<challenge_entry> entries;       // xpbd first
  std::vector<std::string> verdict_criteria;  // accuracy, stability, speed
  std::vector<std::string> verdicts;
  std::vector<small_steps_row> small_steps;
  std::vector<std::string> small_steps_verdicts;  // one line a problem
  double seconds = 0.0;
};

}  // namespace stepbench

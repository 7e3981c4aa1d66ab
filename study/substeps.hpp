#pragma once
// "Small steps or one implicit step?" Macklin et al., Small Steps in Physics Simulation
// (SCA 2019), report that n small explicit steps per frame beat one implicit step with
// n solver iterations on stiff systems. Measured here on stiff_spring, spring_chain and
// n_pendulum at a frame of horizon / 32 (60 Hz with their defaults), one implicit_euler
// (and one implicit_midpoint) step per frame against n substeps of semi_implicit_euler,
// velocity_verlet and xpbd (one constraint pass a substep: the paper's own method),
// n = 1 .. 64, each run and measured like every study row
// (position error over the run against the truth at the frame ends), plus the
// artificial damping: the largest energy removed beyond the true damper's loss over the
// run, max_j (E_true(t_j) - E(t_j)) / energy_scale. At equal cost per frame (the
// measured time when the study is timed, else force evaluations), the verdict says how
// many substeps the implicit step's cost buys and what they achieve.
#include <string>
#include <vector>

#include "core/method.hpp"
#include "study/method_row.hpp"

namespace stepbench {

struct substep_row {
  int substeps = 1;
  method_row row;              // param = dt = frame / substeps
  double extra_damping = 0.0;  // max_j (E_true - E) / energy_scale; NaN without energy or when not completed
};

struct substep_method {
  method_info info;
  std::vector<substep_row> rows;
};

struct substep_study {
  std::string problem;
  double frame_dt = 0.0;
  std::vector<substep_method> methods;
};

struct substep_verdict {
  std::string problem, implicit_method, explicit_method, cost_kind;  // cost_kind: time_ns or force_evals
  double implicit_cost = 0.0, implicit_error = 0.0, implicit_damping = 0.0;
  int substeps_at_equal_cost =
      0;  // the most substeps that cost no more than the implicit step (0: even one costs more)
  double explicit_cost = 0.0, explicit_error = 0.0, explicit_damping = 0.0;  // at that n (NaN if 0)
  int substeps_to_match = 0;   // the fewest substeps whose error is at most the implicit step's (0: none)
  double cost_to_match = 0.0;  // their cost (NaN if none)
  std::string summary;         // one line, as measured
};

}  // namespace stepbench

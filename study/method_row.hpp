#pragma once
// The single row shape of the study: one run of one method at one parameter, with its
// timing when the study was timed (the sweep, the substeps and scan studies share it).
#include <limits>
#include <string>

#include "core/concepts.hpp"
#include "core/measure.hpp"

namespace stepbench {

// Wall time of one whole run, from the benchmark (absent unless timed).
struct timing {
  double time_ns = std::numeric_limits<double>::quiet_NaN();      // median over repetitions
  double time_ns_min = std::numeric_limits<double>::quiet_NaN();  // fastest repetition
  double time_ns_max = std::numeric_limits<double>::quiet_NaN();  // slowest repetition
  long repetitions = 0;
  bool cut = false;  // skipped by the per-case time budget
};

// One run of one method at one parameter: the single row shape of the study.
struct method_row {
  double param = 0.0;  // dt [s] or relative tolerance
  long steps = 0;
  long rejected_steps = 0;
  work_counters work{};
  run_metrics metrics;
  timing time;
};

// A run not taken because its work would exceed the budget: no steps, NaN errors, the
// reason in the note. The sweep's ladder and the scan record the same row.
inline method_row skipped_row(double param, const std::string& note) {
  method_row row{param, 0, 0, {}, {}, {}};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto& mt = row.metrics;
  mt.err_pos_final = mt.err_vel_final = mt.err_pos_max = mt.err_pos_rms = mt.energy_drift = mt.energy_err_max = nan;
  mt.angmom_drift = mt.angmom_err_max = mt.contact_count_err = mt.contact_time_err = mt.contact_pos_err = nan;
  mt.skipped = true;
  mt.note = note;
  return row;
}

}  // namespace stepbench

#pragma once
// One fixed-step run of a method on a problem, recorded at `samples` evenly spaced times:
// the drive loop the study runs, called directly (the contact and force tests).
#include "core/drive.hpp"

namespace stepbench::test_support {

template <class P, class I>
drive_result<typename P::vec> run_fixed(const P& p, const I& method, double dt, int samples = 4) {
  const auto times = sample_times(p.horizon(), samples);
  const auto plan = plan_records(p.horizon(), dt, times);
  return drive(p, method, dt, p.horizon(), plan);
}

}  // namespace stepbench::test_support

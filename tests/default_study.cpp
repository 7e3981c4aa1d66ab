#include "default_study.hpp"

namespace stepbench::test_support {

const study& default_study() {
  // The challenge times its runs and runs 1000 s of motion: tests/test_xpbd.cpp checks
  // it at a shorter horizon, so the shared default study leaves it out.
  static const study s = [] {
    sweep_options o;
    o.challenge.enabled = false;
    return run_sweep(o);
  }();
  return s;
}

}  // namespace stepbench::test_support

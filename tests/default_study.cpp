#include "default_study.hpp"

namespace stepbench::test_support {

const study& default_study() {
  // The parts these tests read: the sweep's rows, and the verdict judged from them. (The
  // other parts have tests of their own, each on a study of just that part.)
  static const study s = [] {
    sweep_options o;
    o.parts = {"sweep", "verdict"};
    return run_sweep(o);
  }();
  return s;
}

}  // namespace stepbench::test_support

// The default study (run_sweep with default options), computed once per test process
// and shared by the tests that read it (test_sweep.cpp, test_accuracy_fixture.cpp).
// It is the costliest thing the suite computes (about 90 s of CPU time in Release, some
// 5 min under the sanitizers on shorter ladders), so those tests run in one process: see
// tests/CMakeLists.txt.
#pragma once

#include "parts/study.hpp"
#include "run/sweep.hpp"

namespace stepbench::test_support {

const study& default_study();

}  // namespace stepbench::test_support

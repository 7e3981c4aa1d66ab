// The default study (run_sweep with default options), computed once per test process
// and shared by the tests that read it (test_sweep.cpp, test_accuracy_fixture.cpp).
// It is the costliest thing the suite computes (about 20 s in Release, about 4 min
// under the sanitizers), so those tests run in one process: see tests/CMakeLists.txt.
#pragma once

#include "parts/study.hpp"
#include "run/sweep.hpp"

namespace stepbench::test_support {

const study& default_study();

}  // namespace stepbench::test_support

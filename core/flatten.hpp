#pragma once
// STEPBENCH_FLATTEN marks a hot loop [[gnu::flatten]]: everything it calls (the step,
// the force model, Eigen's expressions) is inlined into it, which is what makes the
// Release build's loops as fast as a hand-written one (core/drive.hpp). The Sanitize
// build defines STEPBENCH_NO_FLATTEN and leaves inlining to the compiler: flattening
// instrumented code multiplies its compile time (over ten CPU-minutes for one of the
// former four-problem shards), and the sanitizers check the same code either way.
#ifdef STEPBENCH_NO_FLATTEN
#define STEPBENCH_FLATTEN
#else
#define STEPBENCH_FLATTEN [[gnu::flatten]]
#endif

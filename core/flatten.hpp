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

namespace stepbench {

// Calls f() out of line, where a flattened loop would otherwise inline it with all it
// calls: the once-a-run and once-a-contact parts of a loop (the first step size, a
// contact located on the dense output, a stop's message) need no speed. Flattened into the
// adaptive loops they made each problem's unit compile up to 1.4x as long (n_pendulum:
// 54 s against 38 s, measured alone on the 2-core machine); the loops' speed is unchanged
// (the adaptive benchmarks on pendulum, kepler, n_pendulum and damped_spring, within the
// run-to-run spread).
template <class F>
[[gnu::noinline]] decltype(auto) out_of_line(F&& f) {
  return f();
}

}  // namespace stepbench

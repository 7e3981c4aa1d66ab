#pragma once
// Cost against size: the Google Benchmark family spring_chain/<integrator>/masses:<N>
// (N = 8 .. 65536, a fixed number of steps per run, counter ns_per_mass_step, Google
// Benchmark's O(N) complexity fit), and a STREAM-style triad a = b + s c that measures
// this machine's memory bandwidth in the same executable, for scale.
namespace stepbench::bench {

void register_scaling();

}  // namespace stepbench::bench

#pragma once
// Cost against size: the Google Benchmark families spring_chain/<integrator>/masses:<N>
// (N = 8 .. 65536, a fixed number of steps per run, counter ns_per_mass_step) and
// bouncing_balls/<integrator>/balls:<N> (N = 1000 .. 1e6, counter ns_per_ball_step), each
// with Google Benchmark's O(N) complexity fit, and a STREAM-style triad a = b + s c that
// measures this machine's memory bandwidth in the same executable, for scale.
#include <string>
#include <vector>

namespace stepbench::bench {

// The family of each selected scaling problem (every --problem selects its own; an empty
// selection selects every problem), and the triad when either is selected.
void register_scaling(const std::vector<std::string>& problems);

}  // namespace stepbench::bench

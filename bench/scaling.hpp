#pragma once
// Cost against size: the Google Benchmark family spring_chain/<integrator>/masses:<N>
// (N = 8 .. 65536, a fixed number of steps per run, counter ns_per_mass_step, Google
// Benchmark's O(N) complexity fit), and a STREAM-style triad a = b + s c that measures
// this machine's memory bandwidth in the same executable, for scale (bench/scaling.cpp);
// and the family bouncing_balls/<integrator>/balls:<N> (bench/balls.cpp).
#include <string>
#include <vector>

namespace stepbench::bench {

// Whether a scaling family of `problem` runs: every --problem selects its own (an empty
// selection selects every problem).
bool selected(const std::vector<std::string>& problems, const std::string& problem);

// The chain family when spring_chain is selected; the triad when either scaling family is.
void register_scaling(const std::vector<std::string>& problems);
// The balls family when bouncing_balls is selected.
void register_balls(const std::vector<std::string>& problems);

}  // namespace stepbench::bench

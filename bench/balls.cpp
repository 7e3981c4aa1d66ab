// Cost against size for the lecture's closing program: the Google Benchmark family
// bouncing_balls/<integrator>/balls:<N>, N = 1000 .. 1e6, counter ns_per_ball_step,
// Google Benchmark's O(N) complexity fit. Each run is 8 steps of dt = 1 ms of the
// bouncing_balls scene at N balls (problems/bouncing_balls.hpp: the box grows with N to
// keep the density, so a ball meets as many neighbours at every size): the integrator's
// step, the gravity force and the end_of_step contact pass with its grid broad phase,
// timed whole like every run (the scene's set-up is in it: about 3 % at N = 1e6). The
// target: the cost per ball-step at 1e6 within 2x of that at 1000, where everything fits
// in the caches.
//
// Registered by main when bouncing_balls is selected (every problem, or --problem=
// bouncing_balls); --benchmark_filter=bouncing_balls/ then selects it alone.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <chrono>
#include <functional>
#include <string>

#include "bench/scaling.hpp"
#include "registry/registry.hpp"

namespace stepbench::bench {
namespace {

constexpr double balls_dt = 1e-3;
constexpr int balls_steps = 8;
constexpr long ball_counts[] = {1000, 10000, 100000, 1000000};

void balls_case(benchmark::State& state, const std::string& method) {
  const long n = state.range(0);
  auto problem = make_problem("bouncing_balls");
  problem->set("balls", static_cast<double>(n));
  if (const auto err = problem->validate(); !err.empty()) {
    state.SkipWithError(err.c_str());
    return;
  }
  const std::function<double()> run = problem->timed_run(method, balls_dt, balls_steps * balls_dt, {});
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) benchmark::DoNotOptimize(run());
  const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  const double ball_steps = static_cast<double>(state.iterations()) * balls_steps * static_cast<double>(n);
  state.counters["ns_per_ball_step"] = ns / ball_steps;
  state.counters["balls"] = static_cast<double>(n);
  state.SetComplexityN(n);
}

}  // namespace

void register_balls(const std::vector<std::string>& problems) {
  if (!selected(problems, "bouncing_balls")) return;
  for (const auto& m : make_problem("bouncing_balls")->methods()) {  // those that run on it
    if (m.origin != method_origin::ours) continue;
    // Explicit fixed-step methods: what a game steps a ball pit with. An implicit step
    // would difference the 2N-coordinate force for its Jacobian (no analytic one here).
    if (m.kind != method_kind::fixed_step || m.traits.needs_jacobian) continue;
    auto* b = benchmark::RegisterBenchmark(fmt::format("bouncing_balls/{}", m.name).c_str(),
                                           [name = m.name](benchmark::State& state) { balls_case(state, name); });
    b->ArgName("balls");
    for (long n : ball_counts) b->Arg(n);
    b->Complexity(benchmark::oN)->UseRealTime()->Unit(benchmark::kMillisecond);
  }
}

}  // namespace stepbench::bench

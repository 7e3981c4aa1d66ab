#include "bench/scaling.hpp"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "registry/registry.hpp"
#include "store/bench_merge.hpp"

namespace stepbench::bench {
namespace {

// The chain's step is stable for every explicit method at every size here: its fastest
// mode is w_max ~ 2 sqrt(k_s N / m_rope) = 5.1e4 rad/s at N = 65536 (k_s = 1e4 N/m, a 1 kg
// rope), so w_max dt = 0.51 with dt = 1e-5 s. 16 steps a run, no samples recorded: the
// time is the step's.
constexpr double scaling_dt = 1e-5;
constexpr int scaling_steps = 16;
constexpr long chain_sizes[] = {8, 64, 512, 4096, 32768, 65536};

// The balls family (a ball pit, the lecture's closing program): 8 steps of dt = 1 ms of the
// bouncing_balls scene at N balls (problems/bouncing_balls.hpp: the box grows with N to
// keep the density, so a ball meets as many neighbours at every size): the integrator's
// step, the gravity force and the end_of_step contact pass with its grid broad phase,
// timed whole like every run (the scene's set-up is in it: about 3 % at N = 1e6). The
// target: the cost per ball-step at 1e6 within 2x of that at 1000, where everything fits
// in the caches.
constexpr double balls_dt = 1e-3;
constexpr int balls_steps = 8;
constexpr long ball_counts[] = {1000, 10000, 100000, 1000000};

// A family of cost against size: `problem` with its parameter `size` at state.range(0),
// `steps` steps of `dt` a run with no samples recorded, timed whole; the counters
// ns_per_<unit>_step and the size, and Google Benchmark's O(N) fit.
struct size_family {
  const char *problem, *size, *unit;
  double dt;
  int steps;
  std::span<const long> sizes;
  benchmark::TimeUnit time_unit;
};

void size_case(benchmark::State& state, const size_family& f, const std::string& method) {
  const long n = state.range(0);
  auto problem = make_problem(f.problem);
  problem->set(f.size, static_cast<double>(n));
  if (const auto err = problem->validate(); !err.empty()) {
    state.SkipWithError(err.c_str());
    return;
  }
  const std::function<double()> run = problem->timed_run(method, f.dt, f.steps * f.dt, {});
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) benchmark::DoNotOptimize(run());
  const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  const double unit_steps = static_cast<double>(state.iterations()) * f.steps * static_cast<double>(n);
  state.counters[fmt::format("ns_per_{}_step", f.unit)] = ns / unit_steps;
  state.counters[f.size] = static_cast<double>(n);
  state.SetComplexityN(n);
}

// The family's cases, one for each of our fixed-step methods that runs on the problem
// (xpbd included) and `takes` it.
template <class Takes>
void register_family(const size_family& f, Takes takes) {
  for (const auto& m : make_problem(f.problem)->methods()) {
    if (m.origin != method_origin::ours || m.kind != method_kind::fixed_step || !takes(m)) continue;
    auto* b = benchmark::RegisterBenchmark(fmt::format("{}/{}", f.problem, m.name).c_str(),
                                           [&f, name = m.name](benchmark::State& state) { size_case(state, f, name); });
    b->ArgName(f.size);
    for (long n : f.sizes) b->Arg(n);
    b->Complexity(benchmark::oN)->UseRealTime()->Unit(f.time_unit);
  }
}

// STREAM's triad (McCalpin, "Memory Bandwidth and Machine Balance", IEEE TCCA newsletter
// 1995): a[i] = b[i] + s c[i] over three arrays of n doubles, 24 bytes moved per element
// (STREAM's own count: two reads and one write; a write-allocate adds a read of a, which
// STREAM does not count). Large n measures main memory; the chain's size measures the
// caches its state fits in.
void triad(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  for (auto _ : state) {
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(24 * n));
  state.counters["doubles"] = static_cast<double>(n);
}

bool selected(const std::vector<std::string>& problems, const std::string& problem) {
  return problems.empty() || std::find(problems.begin(), problems.end(), problem) != problems.end();
}

}  // namespace

void register_scaling(const std::vector<std::string>& problems) {
  static const size_family chain{"spring_chain",         "masses", "mass", scaling_dt, scaling_steps, chain_sizes,
                                 benchmark::kMicrosecond};
  static const size_family balls{"bouncing_balls",       "balls", "ball", balls_dt, balls_steps, ball_counts,
                                 benchmark::kMillisecond};
  const bool chain_selected = selected(problems, "spring_chain"), balls_selected = selected(problems, "bouncing_balls");
  if (chain_selected) register_family(chain, [](const method_info&) { return true; });
  // 2^25 doubles (256 MiB) an array: far beyond every cache of the machines here; and the
  // size of one vector of the 65536-mass chain's state (3 x 65536 doubles).
  // Of the machine, not a problem: every shard with a scaling family runs it, and `stepbench
  // merge --bench` keeps each shard's (store/bench_merge.hpp).
  if (chain_selected || balls_selected)
    benchmark::RegisterBenchmark(std::string(stream_triad_benchmark).c_str(), triad)
        ->ArgName("doubles")
        ->Arg(1L << 25)
        ->Arg(3L * 65536)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  // Explicit methods only: what a game steps a ball pit with. An implicit step would
  // difference the 2N-coordinate force for its Jacobian (no analytic one here).
  if (balls_selected) register_family(balls, [](const method_info& m) { return !m.traits.needs_jacobian; });
}

}  // namespace stepbench::bench

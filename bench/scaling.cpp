#include "bench/scaling.hpp"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
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

void chain_case(benchmark::State& state, const std::string& method) {
  const long n = state.range(0);
  auto problem = make_problem("spring_chain");
  problem->set("masses", static_cast<double>(n));
  const std::function<double()> run = problem->timed_run(method, scaling_dt, scaling_steps * scaling_dt, {});
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) benchmark::DoNotOptimize(run());
  const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  const double mass_steps = static_cast<double>(state.iterations()) * scaling_steps * static_cast<double>(n);
  state.counters["ns_per_mass_step"] = ns / mass_steps;
  state.counters["masses"] = static_cast<double>(n);
  state.SetComplexityN(n);
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

}  // namespace

bool selected(const std::vector<std::string>& problems, const std::string& problem) {
  return problems.empty() || std::find(problems.begin(), problems.end(), problem) != problems.end();
}

void register_scaling(const std::vector<std::string>& problems) {
  const bool chain = selected(problems, "spring_chain");
  if (!chain && !selected(problems, "bouncing_balls")) return;
  for (const auto& m : make_problem("spring_chain")->methods()) {  // ours that run on it, xpbd included
    if (!chain || m.origin != method_origin::ours || m.kind != method_kind::fixed_step) continue;
    auto* b = benchmark::RegisterBenchmark(fmt::format("spring_chain/{}", m.name).c_str(),
                                           [name = m.name](benchmark::State& state) { chain_case(state, name); });
    b->ArgName("masses");
    for (long n : chain_sizes) b->Arg(n);
    b->Complexity(benchmark::oN)->UseRealTime()->Unit(benchmark::kMicrosecond);
  }
  // 2^25 doubles (256 MiB) an array: far beyond every cache of the machines here; and the
  // size of one vector of the 65536-mass chain's state (3 x 65536 doubles).
  // Of the machine, not a problem: every shard with a scaling family runs it, and `stepbench
  // merge --bench` keeps each shard's (store/bench_merge.hpp).
  benchmark::RegisterBenchmark(std::string(stream_triad_benchmark).c_str(), triad)
      ->ArgName("doubles")
      ->Arg(1L << 25)
      ->Arg(3L * 65536)
      ->UseRealTime()
      ->Unit(benchmark::kMillisecond);
}

}  // namespace stepbench::bench

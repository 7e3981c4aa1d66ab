// Google Benchmark timing of one whole integration per (problem, integrator), with the
// step loop instantiated directly (no registry in the timed path). Registered at run
// time from the type lists: names <problem>/<integrator>/dt:<value>.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "core/drive.hpp"
#include "integrators/all.hpp"
#include "problems/all.hpp"

using namespace stepbench;

int main(int argc, char** argv) {
  for_each_type(all_problems{}, [&]<class P>() {
    for_each_type(all_integrators{}, [&]<class I>() {
      const P problem{};
      const double horizon = problem.horizon();
      const double dt = horizon / 1024.0;  // level 5 of the default sweep ladder (32 * 2^5 steps)
      const std::vector<long> record{steps_for(horizon, dt)};
      auto* b = benchmark::RegisterBenchmark(
          fmt::format("{}/{}/dt:{:.6g}", P::name, I::name, dt).c_str(), [=](benchmark::State& state) {
            long steps = 0, evals = 0;
            for (auto _ : state) {
              const auto r = drive(problem, I{}, dt, horizon, record);
              benchmark::DoNotOptimize(r.final_state.x.data());
              steps = r.steps;
              evals = r.force_evals;
            }
            state.counters["steps"] = static_cast<double>(steps);
            state.counters["force_evals"] = static_cast<double>(evals);
            state.counters["ns_per_step"] =
                benchmark::Counter(static_cast<double>(steps) * 1e-9, benchmark::Counter::kIsIterationInvariantRate |
                                                                          benchmark::Counter::kInvert);
          });
      b->Unit(benchmark::kMicrosecond);
    });
  });
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

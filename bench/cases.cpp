#include "bench/cases.hpp"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <chrono>
#include <stdexcept>

#include "core/statistics.hpp"

namespace stepbench::bench {

void case_book::add(const problem_study& ps, const method_info& info, method_row& row, std::string name,
                    std::string family) {
  if (!row.metrics.completed()) return;
  auto c = std::make_unique<timed_case>();
  c->name = std::move(name);
  c->family = std::move(family);
  c->row = &row;
  if (!by_name_.emplace(c->name, c.get()).second)
    throw std::logic_error("two benchmark cases would share the name " + c->name);
  const std::function<double()> run = ps.problem->timed_run(info.name, row.param, ps.horizon, ps.truth.times);
  benchmark::RegisterBenchmark(
      c->name.c_str(),
      [this, tc = c.get(), run](benchmark::State& state) {
        if (over_budget(*tc)) {
          state.SkipWithError("cut: the previous case of this family used over half the per-case time budget");
          return;
        }
        const auto start = std::chrono::steady_clock::now();
        for (auto _ : state) benchmark::DoNotOptimize(run());
        const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() /
                          static_cast<double>(std::max<benchmark::IterationCount>(1, state.iterations()));
        record(*tc, ns);
        const method_row& r = *tc->row;  // the accuracy counters: the row the sweep measured
        state.counters["err_pos_final"] = r.metrics.err_pos_final;
        state.counters["err_pos_max"] = r.metrics.err_pos_max;
        state.counters["steps"] = static_cast<double>(r.steps);
        state.counters["force_evals"] = static_cast<double>(r.work.force_evals);
        if (r.rejected_steps) state.counters["rejected_steps"] = static_cast<double>(r.rejected_steps);
        if (r.work.newton_iterations)
          state.counters["newton_iterations"] = static_cast<double>(r.work.newton_iterations);
        if (r.work.jacobian_evals) state.counters["jacobian_evals"] = static_cast<double>(r.work.jacobian_evals);
        // Wall time per step (the case uses real time): Google Benchmark divides the elapsed
        // time by steps x iterations (an inverted iteration-invariant rate) and prints it in
        // seconds with an SI prefix (13.8n = 13.8 ns).
        state.counters["time_per_step"] =
            benchmark::Counter(static_cast<double>(std::max(1L, r.steps)),
                               benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
      })
      ->Unit(benchmark::kMicrosecond)
      ->UseRealTime();
  cases_.push_back(std::move(c));
}

void case_book::register_all(study& s) {
  for (auto& ps : s.problems) {
    const std::string pname(ps.problem->name());
    for (auto& ms : ps.methods) {
      const bool fixed = ms.info.kind == method_kind::fixed_step;
      for (auto& row : ms.rows)
        add(ps, ms.info, row, fmt::format("{}/{}/{}:{:.6g}", pname, ms.info.name, fixed ? "dt" : "tol", row.param),
            pname + "/" + ms.info.name);
    }
  }
  // The small-steps comparison (study/substeps.hpp): each of its runs, timed the same way.
  auto* substeps = s.results.find<std::vector<substep_study>>();
  if (!substeps) return;
  for (auto& st : *substeps)
    if (const problem_study* ps = s.find(st.problem))
      for (auto& m : st.methods)
        for (auto& r : m.rows)
          add(*ps, m.info, r.row, fmt::format("substeps/{}/{}/n:{}", st.problem, m.info.name, r.substeps),
              "substeps/" + st.problem + "/" + m.info.name);
}

timed_case* case_book::find(const std::string& registered_name) {
  const auto it = by_name_.find(registered_name);
  return it == by_name_.end() ? nullptr : it->second;
}

bool case_book::over_budget(const timed_case& c) const {
  const auto it = family_last_.find(c.family);
  return it != family_last_.end() && it->second.first != &c && 2.0 * it->second.second > budget_s_ * 1e9;
}

void case_book::record(const timed_case& c, double ns) {
  auto& last = family_last_[c.family];
  last.second = last.first == &c ? std::max(last.second, ns) : ns;
  last.first = &c;
}

void case_book::merge_into_rows() {
  for (const auto& c : cases_) {
    timing& t = c->row->time;
    t = {};
    if (!c->ns_per_run.empty()) {
      t.time_ns = median(c->ns_per_run);
      t.time_ns_min = *std::min_element(c->ns_per_run.begin(), c->ns_per_run.end());
      t.time_ns_max = *std::max_element(c->ns_per_run.begin(), c->ns_per_run.end());
      t.repetitions = static_cast<long>(c->ns_per_run.size());
    } else {
      t.cut = c->skipped.rfind("cut", 0) == 0;
    }
  }
}

std::size_t case_book::timed_count() const {
  std::size_t n = 0;
  for (const auto& c : cases_) n += !c->ns_per_run.empty();
  return n;
}

}  // namespace stepbench::bench

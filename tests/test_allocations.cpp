// No heap allocation inside the step loop, for any of our integrators on any problem:
// the integrators keep their workspace, sized once per run. This binary replaces the
// global operator new and, because Eigen allocates with malloc rather than new,
// interposes malloc, calloc, realloc and the aligned variants too (glibc resolves them in
// the executable first), counting every call. A run of 2N steps must then allocate
// exactly as often as a run of N steps: whatever a run allocates (the recorded samples,
// the workspace, the result's vectors) is per run, not per step. The runs go through the
// registry (problem_instance::run), the path the study takes, so that this test compiles
// none of the methods itself: they are compiled once, in the study's method units.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "registry/registry.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<long> allocations{0};
}

extern "C" {
void* malloc(std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t count, std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, n);
}
void* realloc(void* p, std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  *out = __libc_memalign(alignment, n);
  return *out ? 0 : ENOMEM;
}
void free(void* p) { __libc_free(p); }
}

void* operator new(std::size_t n) {
  if (void* p = malloc(n)) return p;  // counted in malloc
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { free(p); }
void operator delete[](void* p) noexcept { free(p); }
void operator delete(void* p, std::size_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t) noexcept { free(p); }

using namespace stepbench;

namespace {

template <class F>
long allocations_during(F&& run) {
  const long before = allocations.load();
  run();
  return allocations.load() - before;
}

// The problems, with the chain at 64 masses (a dynamically sized state) and softened
// (k_s = 10 N/m) so that every explicit method is stable at 400 steps: a run that
// diverges stops early, and this test wants every step taken.
template <class F>
void for_each_scene(F&& f) {
  for (const auto& name : problem_names()) {
    auto p = make_problem(name);
    if (name == "spring_chain") {
      p->set("masses", 64);
      p->set("k_s", 10.0);
    }
    f(*p);
  }
}

// Our methods of the given kind that run on the problem.
std::vector<std::string> ours(const problem_instance& p, method_kind kind) {
  std::vector<std::string> out;
  for (const auto& m : p.methods())
    if (m.origin == method_origin::ours && m.kind == kind) out.push_back(m.name);
  return out;
}

}  // namespace

TEST(allocations, counting_sees_eigen_and_new) {
  const long n = allocations_during([] {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(1000);  // Eigen: malloc
    auto* i = new int(3);                             // operator new
    volatile double keep = v.sum() + *i;
    (void)keep;
    delete i;
  });
  EXPECT_EQ(n, 2);
}

TEST(allocations, none_per_step_fixed_step) {
  int runs = 0;
  for_each_scene([&](const problem_instance& p) {
    const double horizon = p.horizon();
    const std::vector<double> times = sample_times(horizon, 4);
    for (const auto& method : ours(p, method_kind::fixed_step)) {
      // A run that fails (implicit Euler's Newton finds no root on the orbit's periapsis
      // at 400 steps) is not a step loop to count in; the sweep records it as failed.
      bool failed = false;
      auto run = [&](long steps) {
        const double dt = horizon / static_cast<double>(steps);
        return allocations_during([&] {
          const run_result r = p.run(method, dt, horizon, times, run_limits{});
          failed = failed || !r.stop_reason.empty() || r.non_finite;
          if (!failed) {
            EXPECT_EQ(r.steps, steps) << p.name() << "/" << method;
          }
        });
      };
      const long a = run(400), b = run(800);
      if (failed) continue;
      ++runs;
      EXPECT_EQ(a, b) << p.name() << "/" << method << ": " << a << " allocations for 400 steps, " << b << " for 800";
    }
  });
  EXPECT_GE(runs, 100);  // 14 problems, 10 fixed-step methods (and xpbd on 5), few failures
}

TEST(allocations, none_per_step_adaptive) {
  int runs = 0;
  run_limits limits;
  limits.work_budget = 1e15;
  limits.max_steps = 1L << 22;
  for_each_scene([&](const problem_instance& p) {
    const double horizon = p.horizon();
    const std::vector<double> times = sample_times(horizon, 4);
    for (const auto& method : ours(p, method_kind::adaptive)) {
      long steps[2] = {0, 0}, count[2] = {0, 0};
      bool completed = true;
      const double tol[2] = {1e-3, 1e-4};
      for (int k = 0; k < 2; ++k)
        count[k] = allocations_during([&] {
          const run_result r = p.run(method, tol[k], horizon, times, limits);
          steps[k] = r.steps;
          completed = completed && r.stop_reason.empty() && !r.non_finite;
        });
      if (!completed) continue;  // adaptive Euler on the stiff scenes: over its step budget
      ++runs;
      // rk45 is exact on a constant force and takes the same steps at both tolerances.
      EXPECT_LE(steps[0], steps[1]) << p.name() << "/" << method;
      EXPECT_EQ(count[0], count[1]) << p.name() << "/" << method << ": " << count[0] << " allocations for " << steps[0]
                                    << " steps, " << count[1] << " for " << steps[1];
    }
  });
  EXPECT_GE(runs, 30);  // 14 problems, 3 adaptive methods
}

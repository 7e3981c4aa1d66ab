// No heap allocation inside the step loop, for any integrator on any problem: the
// integrators keep their workspace, sized once per run. This binary replaces the global
// operator new and, because Eigen allocates with malloc rather than new, interposes
// malloc, calloc, realloc and the aligned variants too (glibc resolves them in the
// executable first), counting every call. A run of 2N steps must then allocate exactly
// as often as a run of N steps: whatever a run allocates (the recorded samples, the
// workspace) is per run, not per step.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <stdexcept>

#include "core/drive.hpp"
#include "integrators/all.hpp"
#include "problems/all.hpp"

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
  for_each_type(all_problems{}, [&]<class P>() {
    P p{};
    if constexpr (std::is_same_v<P, spring_chain>) {
      p.masses = 64;
      p.k_s = 10.0;
    }
    f(p);
  });
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
  for_each_scene([&](const auto& p) {
    using P = std::decay_t<decltype(p)>;
    const std::vector<double> times = sample_times(p.horizon(), 4);
    for_each_type(all_integrators{}, [&]<class I>() {
      if constexpr (integrator<I>) {
        // A run that fails (implicit Euler's Newton finds no root on the orbit's periapsis
        // at 400 steps) is not a step loop to count in; the sweep records it as failed.
        bool failed = false;
        auto run = [&](long steps) {
          const double dt = p.horizon() / static_cast<double>(steps);
          const auto plan = plan_records(p.horizon(), dt, times);
          return allocations_during([&] {
            try {
              const auto r = drive(p, I{}, dt, p.horizon(), plan);
              EXPECT_EQ(r.steps, steps) << P::name << "/" << I::name;
            } catch (const std::runtime_error&) {
              failed = true;
            }
          });
        };
        const long a = run(400), b = run(800);
        if (failed) return;
        EXPECT_EQ(a, b) << P::name << "/" << I::name << ": " << a << " allocations for 400 steps, " << b << " for 800";
      }
    });
  });
}

TEST(allocations, none_per_step_adaptive) {
  for_each_scene([&](const auto& p) {
    using P = std::decay_t<decltype(p)>;
    const std::vector<double> times = sample_times(p.horizon(), 4);
    for_each_type(all_integrators{}, [&]<class I>() {
      if constexpr (adaptive_integrator<I>) {
        long steps[2] = {0, 0}, count[2] = {0, 0};
        bool completed = true;
        const double tol[2] = {1e-3, 1e-4};
        for (int k = 0; k < 2; ++k)
          count[k] = allocations_during([&] {
            const auto r = drive_adaptive(p, I(tol[k]), p.horizon(), times, 1L << 22);
            steps[k] = r.steps;
            completed = completed && r.stop_reason.empty();
          });
        if (!completed) return;  // adaptive Euler on the stiff scenes: over its step budget
        // rk45 is exact on a constant force and takes the same steps at both tolerances.
        EXPECT_LE(steps[0], steps[1]) << P::name << "/" << I::name;
        EXPECT_EQ(count[0], count[1]) << P::name << "/" << I::name << ": " << count[0] << " allocations for "
                                      << steps[0] << " steps, " << count[1] << " for " << steps[1];
      }
    });
  });
}

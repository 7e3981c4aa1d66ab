#pragma once
// A plugin's method (include/stepbench/plugin.h) as an integrator of ours: a small value
// type holding the plugin's method table, whose stepper steps through the plugin's C
// function and so runs in drive() / drive_adaptive() like our methods (the same grid,
// landing, recording, contacts, finiteness checks and counting). Instantiated once a
// problem, in its unit (registry/problem_model.hpp): the plugin's step is an indirect
// call, the force behind it the problem's own, inlined into one callback.
//
// The force callback maps the plugin's double arrays onto the problem's vectors: the
// problem's force takes `const vec&`, so x (and v, where the force depends on it) of a
// plugin's own stage are copied into vectors sized once a run (the step's state is read
// where it is); nothing a step allocates. It returns
// a = F / m, as plugin.h says: the host multiplies by 1 / m, which for the default
// problems' masses (powers of two) is exact, so a plugin RK4 in rk4.hpp's order gives
// rk4's results bit for bit (tests/test_plugins.cpp).
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/concepts.hpp"
#include "core/drive.hpp"
#include "core/flatten.hpp"
#include "core/method.hpp"
#include "include/stepbench/plugin.h"
#include "integrators/step_control.hpp"

namespace stepbench::registry_detail {

// Why a plugin's step failed: the reason a run records (out of line: a run's last words).
[[noreturn, gnu::noinline]] void plugin_step_failed(const stepbench_method& m, int status, double t,
                                                    const std::string& host_reason);
[[noreturn, gnu::noinline]] void plugin_bad_proposal(const stepbench_method& m, double dt_next, double t);
[[noreturn, gnu::noinline]] void plugin_no_workspace(const stepbench_method& m, int n);

// What the force callback needs: the counted system, vectors of the problem's type, and
// the cap on force evaluations (twice the run's work budget over the coordinates: the
// sweep runs a level only when it predicts it within the budget, so a run past twice
// that evaluates more than it declares; plugin.h's STEPBENCH_HOST_STOP ends it).
template <class Sys>
struct plugin_force_context {
  using Vec = typename Sys::vec;
  const Sys* sys = nullptr;
  const step_state<Vec>* state = nullptr;  // the step's state: read in place when the plugin passes it
  Vec x, v, f;
  double inverse_mass = 1.0;
  long max_evals = std::numeric_limits<long>::max();
  std::string stop_reason;  // set when the callback refused: the run's reason

  void bind(const Sys& s, const Vec& like, double work_budget) {
    sys = &s;
    size_like(like, x, v, f);
    inverse_mass = stepbench::inverse_mass(s);
    const double cap = 2.0 * work_budget / static_cast<double>(like.size());
    if (cap < static_cast<double>(max_evals)) max_evals = static_cast<long>(cap);
  }
};

// The callback plugin.h's stepbench_force_fn points to. Flattened: the problem's force
// and Eigen's copies inline into it. It never throws into the plugin's C frames.
template <class Sys>
STEPBENCH_FLATTEN int plugin_force(void* ctx, double t, const double* x, const double* v, double* a) noexcept {
  using Vec = typename Sys::vec;
  auto& c = *static_cast<plugin_force_context<Sys>*>(ctx);
  if (c.sys->work.force_evals >= c.max_evals) {
    if (c.stop_reason.empty())
      out_of_line(
          [&] { c.stop_reason = "over twice the work budget: " + std::to_string(c.max_evals) + " force evaluations"; });
    return STEPBENCH_HOST_STOP;
  }
  const Eigen::Index n = c.x.size();
  // The state the host gave the step (a method's first stage, or ruth3's every one) is
  // read where it is; a stage of the plugin's own is copied in.
  const bool in_place = x == c.state->x.data() && v == c.state->v.data();
  if (!in_place) {
    c.x = Eigen::Map<const Vec>(x, n);
    if constexpr (Sys::force_depends_on_velocity) c.v = Eigen::Map<const Vec>(v, n);
  }
  try {
    c.sys->force(t, in_place ? c.state->x : c.x, in_place ? c.state->v : c.v, c.f);
  } catch (const std::exception& e) {
    out_of_line([&] { c.stop_reason = e.what(); });
    return STEPBENCH_HOST_STOP;
  }
  Eigen::Map<Vec>(a, n) = c.inverse_mass * c.f;
  return STEPBENCH_OK;
}

// The workspace a plugin creates for n coordinates, owned: destroyed with the stepper.
struct plugin_workspace {
  const stepbench_method* m;
  void* w = nullptr;
  explicit plugin_workspace(const stepbench_method* method) : m(method) {}
  plugin_workspace(const plugin_workspace&) = delete;
  plugin_workspace& operator=(const plugin_workspace&) = delete;
  ~plugin_workspace() {
    if (w != nullptr) m->destroy(w);
  }
  void create(int n) {
    if (w == nullptr) w = m->create(n);
    if (w == nullptr) plugin_no_workspace(*m, n);
  }
};

// The descriptor parts every integrator has (core/concepts.hpp); a plugin's own name,
// order and capabilities are in its method_info, which the registry takes from the plugin.
struct plugin_described {
  static constexpr std::string_view name = "plugin";
  static constexpr std::string_view description = "a method from a plugin (include/stepbench/plugin.h)";
  static constexpr int order = 0;
  static constexpr capabilities traits{};
  const stepbench_method* method = nullptr;
  double work_budget = std::numeric_limits<double>::infinity();
};

// A fixed-step plugin method, run by drive().
struct plugin_fixed : plugin_described {
  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    plugin_workspace ws;
    double work_budget;
    plugin_force_context<Sys> ctx;
    explicit stepper(const plugin_fixed& p) : ws(p.method), work_budget(p.work_budget) {}
    void resize(const Sys& sys, const Vec& like) {
      ctx.bind(sys, like, work_budget);
      ws.create(static_cast<int>(like.size()));
    }
    void step(const Sys&, double t, step_state<Vec>& s, double dt) {
      ctx.state = &s;
      const int status = ws.m->step(ws.w, t, dt, s.x.data(), s.v.data(), &plugin_force<Sys>, &ctx);
      s.f_current = false;
      if (status != STEPBENCH_OK || !ctx.stop_reason.empty()) plugin_step_failed(*ws.m, status, t, ctx.stop_reason);
    }
  };
};

// An adaptive plugin method, run by drive_adaptive(). The first step is Hairer's starting
// step, as for our adaptive methods (integrators/step_control.hpp); then the plugin's.
struct plugin_adaptive : plugin_described {
  static constexpr int force_evals_per_step = 1;  // the concept's; the budget uses the plugin's own
  double tol = 1e-6;
  plugin_adaptive() = default;
  explicit plugin_adaptive(double tolerance) : tol(tolerance) {}
  plugin_adaptive(const stepbench_method* m, double budget, double tolerance)
      : plugin_described{m, budget}, tol(tolerance) {}

  template <class Sys>
  struct stepper {
    using Vec = typename Sys::vec;
    plugin_workspace ws;
    double work_budget, tol;
    plugin_force_context<Sys> ctx;
    Vec x0, v0, fs;  // the state an attempt began from (restored on rejection); workspace
    explicit stepper(const plugin_adaptive& p) : ws(p.method), work_budget(p.work_budget), tol(p.tol) {}
    void resize(const Sys& sys, const Vec& like) {
      ctx.bind(sys, like, work_budget);
      size_like(like, x0, v0, fs);
      ws.create(static_cast<int>(like.size()));
    }
    double initial_dt(const Sys& sys, double t, step_state<Vec>& s, double horizon) {
      return starting_step(sys, t, s, ws.m->order, tol, horizon, x0, v0, fs);
    }
    step_attempt try_step(const Sys&, double t, step_state<Vec>& s, double dt) {
      x0 = s.x;
      v0 = s.v;
      ctx.state = &s;
      double dt_next = std::numeric_limits<double>::quiet_NaN();
      int accepted = 0;
      const int status =
          ws.m->try_step(ws.w, t, dt, tol, s.x.data(), s.v.data(), &plugin_force<Sys>, &ctx, &dt_next, &accepted);
      s.f_current = false;
      if (status != STEPBENCH_OK || !ctx.stop_reason.empty()) plugin_step_failed(*ws.m, status, t, ctx.stop_reason);
      if (!(dt_next > 0.0) || !std::isfinite(dt_next)) plugin_bad_proposal(*ws.m, dt_next, t);
      if (accepted == 0) {
        s.x = x0;
        s.v = v0;
      }
      return {accepted != 0, dt, dt_next};
    }
  };
};

// A plugin method's run on problem P, prepared as ours are (registry/method_entry.hpp):
// fixed-step on drive() at dt = param, adaptive on drive_adaptive() at tolerance param
// within the adaptive step budget for the plugin's declared evaluations a step.
template <problem P>
auto prepare_plugin(const stepbench_method* m, const P& p, double param, double horizon, std::span<const double> times,
                    const run_limits& limits) {
  const bool fixed = m->kind == STEPBENCH_FIXED_STEP;
  return [p, m, param, horizon, fixed, budget = limits.work_budget,
          plan = fixed ? plan_records(horizon, param, times) : std::vector<record_point>{},
          t = std::vector<double>(times.begin(), times.end()),
          max_steps = limits.adaptive_steps(p.dim(), m->force_evals_per_step)] {
    if (fixed) return drive(p, plugin_fixed{{m, budget}}, param, horizon, plan);
    return drive_adaptive(p, plugin_adaptive(m, budget, param), horizon, t, max_steps);
  };
}

}  // namespace stepbench::registry_detail

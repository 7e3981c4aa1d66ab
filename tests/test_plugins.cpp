// Plugins (docs/plugins.md): the example RK4 gives rk4's errors on every default problem,
// Ruth's method is of order 3, every bad plugin is refused or fails its run as documented,
// and the loader's validation accepts exactly the tables plugin.h allows (a fuzz test).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/drive.hpp"
#include "registry/plugins.hpp"
#include "registry/registry.hpp"

namespace stepbench {
namespace {

std::string plugin_path(const std::string& name) { return std::string(STEPBENCH_PLUGIN_DIR) + "/" + name; }

// Loads a plugin once a process (the tests of this file may share one).
void ensure_loaded(const std::string& path) {
  for (const auto& p : loaded_plugins())
    if (p.path == path) return;
  load_plugin(path);
}

// The message load_plugin refuses `path` with ("" when it loads).
std::string refusal(const std::string& path) {
  try {
    load_plugin(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// The largest position error of a run against a reference run at the same sample times.
double position_error(const run_result& r, const run_result& truth, int dim) {
  double e = 0.0;
  for (std::size_t j = 0; j < r.sample_y.size(); ++j)
    for (int i = 0; i < dim; ++i) e = std::max(e, std::abs(r.sample_y[j][i] - truth.sample_y[j][i]));
  return e;
}

// On every default problem, plugin_rk4 (examples/plugins/rk4.c) at 800 steps takes the
// same states as rk4 and so has the same error, against rk4 at 6400 steps (or the closed
// form where there is one), to relative 1e-13.
TEST(plugins, example_rk4_gives_rk4s_errors_on_every_default_problem) {
  ensure_loaded(plugin_path("librk4.so"));
  for (const auto& name : problem_names()) {
    const auto p = make_problem(name);
    const double horizon = p->horizon(), dt = horizon / 800.0;
    const auto times = nearest_grid_times(horizon, dt, 16);
    const run_limits limits;
    const run_result ours = p->run("rk4", dt, horizon, times, limits);
    const run_result plugin = p->run("plugin_rk4", dt, horizon, times, limits);
    ASSERT_TRUE(plugin.stop_reason.empty()) << name << ": " << plugin.stop_reason;
    ASSERT_EQ(plugin.steps, ours.steps) << name;
    EXPECT_EQ(plugin.work.force_evals, ours.work.force_evals) << name;
    ASSERT_EQ(plugin.sample_y.size(), ours.sample_y.size()) << name;
    run_result truth = p->run("rk4", dt / 8.0, horizon, times, limits);
    if (p->has_closed_form())
      for (std::size_t j = 0; j < times.size(); ++j) truth.sample_y[j] = p->exact(times[j]);
    const double e_ours = position_error(ours, truth, p->dim()), e_plugin = position_error(plugin, truth, p->dim());
    EXPECT_LE(std::abs(e_plugin - e_ours), 1e-13 * e_ours) << name << ": " << e_plugin << " against " << e_ours;
    for (std::size_t j = 0; j < ours.sample_y.size(); ++j)
      for (std::size_t i = 0; i < ours.sample_y[j].size(); ++i)
        EXPECT_LE(std::abs(plugin.sample_y[j][i] - ours.sample_y[j][i]), 1e-13 * std::abs(ours.sample_y[j][i]))
            << name << " sample " << j << " coordinate " << i;
  }
}

// Ruth's method (examples/plugins/ruth3.c) on the pendulum: halving dt divides the error
// by 2^3, and it takes 3 force evaluations a step, as it declares.
TEST(plugins, ruth3_is_third_order_on_the_pendulum) {
  ensure_loaded(plugin_path("libruth3.so"));
  const auto p = make_problem("pendulum");
  const double horizon = p->horizon();
  const auto times = sample_times(horizon, 8);
  std::vector<double> errors;
  for (const int steps : {1024, 2048}) {
    const run_result r = p->run("ruth3", horizon / steps, horizon, times, run_limits{});
    ASSERT_TRUE(r.stop_reason.empty()) << r.stop_reason;
    EXPECT_EQ(r.work.force_evals, 3L * r.steps);
    double e = 0.0;
    for (std::size_t j = 0; j < times.size(); ++j) e = std::max(e, std::abs(r.sample_y[j][0] - p->exact(times[j])[0]));
    errors.push_back(e);
  }
  EXPECT_NEAR(std::log2(errors[0] / errors[1]), 3.0, 0.1) << errors[0] << " " << errors[1];
  const method_info& m = find_method("ruth3");
  EXPECT_EQ(m.origin, method_origin::plugin);
  EXPECT_TRUE(m.traits.symplectic);
  EXPECT_EQ(m.declared_order, 3.0);
}

// A file that is not a plugin, another ABI, a duplicate or built-in name, a bad field:
// refused in one line naming the file and the problem, and nothing registered.
TEST(plugins, bad_plugins_are_refused_in_one_line) {
  const std::size_t methods_before = all_methods().size();
  const auto expect_refused = [](const std::string& path, const std::string& why) {
    const std::string e = refusal(path);
    EXPECT_NE(e.find("plugin " + path + ": "), std::string::npos) << e;
    EXPECT_NE(e.find(why), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  };
  expect_refused(plugin_path("none.so"), "no such file");
  expect_refused(std::string(STEPBENCH_TEST_DATA) + "/../plugins/bad.c", "not a shared library it can load");
  expect_refused(plugin_path("bad/libbad_no_entry.so"),
                 "not a stepbench plugin: it has no function stepbench_plugin()");
  expect_refused(plugin_path("bad/libbad_abi.so"), "it declares plugin ABI version 2; this stepbench reads version 1");
  expect_refused(plugin_path("bad/libbad_reserved.so"), "method 1 (rk4): the name is taken");
  expect_refused(plugin_path("bad/libbad_fields.so"), "method 1 (bad_fields): its order is 0, not 1 to 16");
  EXPECT_EQ(all_methods().size(), methods_before);
  // ruth3 may be loaded already (the cases share a process when the executable runs whole).
  const auto& all = all_methods();
  const bool had_ruth3 = std::any_of(all.begin(), all.end(), [](const method_info& m) { return m.name == "ruth3"; });
  ensure_loaded(plugin_path("libruth3.so"));
  // The same plugin twice: its names are taken by the first.
  expect_refused(plugin_path("libruth3.so"), "method 1 (ruth3): the name is taken");
  EXPECT_EQ(all_methods().size(), methods_before + (had_ruth3 ? 0 : 1));
}

// One run of a bad plugin's method on the pendulum at dt = 0.01 s (552 steps).
run_result run_bad(const std::string& method, const run_limits& limits = {}) {
  ensure_loaded(plugin_path("bad/lib" + method + ".so"));
  const auto p = make_problem("pendulum");
  return p->run(method, 0.01, p->horizon(), sample_times(p->horizon(), 4), limits);
}

// A step that returns an error, writes a NaN, or evaluates past the work budget: that
// run fails with its reason (the sweep records it as a failed row and goes on).
TEST(plugins, a_bad_step_fails_its_run_with_the_reason) {
  const run_result status = run_bad("bad_status");
  EXPECT_EQ(status.stop_reason, "plugin method bad_status returned status 7 at t = 0.51");
  EXPECT_EQ(status.steps, 0);  // the loop's counters are lost with the exception: a failed run
  // The loop checks the state where it records (core/drive.hpp): the first sample time,
  // T / 4 = 1.38 s, after the NaN written at t = 0.52.
  const run_result nan = run_bad("bad_nan");
  EXPECT_TRUE(nan.non_finite);
  EXPECT_EQ(nan.steps, 137);
  EXPECT_TRUE(nan.sample_y.empty());
  // 100001 evaluations a step against a budget of 10^6 coordinate evaluations: stopped at
  // twice that, in its 20th step (from t = 0.19).
  run_limits small;
  small.work_budget = 1e6;
  const run_result greedy = run_bad("bad_greedy", small);
  EXPECT_EQ(greedy.stop_reason,
            "plugin method bad_greedy stopped at t = 0.19: over twice the work budget: 2000000 force evaluations");
}

// An adaptive plugin (tests/plugins/adaptive.c, Heun-Euler) through drive_adaptive: it
// meets the tolerance's scale, its attempts are counted (two evaluations each, and two
// for the host's starting step), a rejected attempt's scribbles are undone by the host,
// and a NaN proposal fails the run with its reason.
TEST(plugins, an_adaptive_plugin_runs_in_drive_adaptive) {
  const auto p = make_problem("pendulum");
  const double horizon = p->horizon();
  const auto times = sample_times(horizon, 8);
  ensure_loaded(plugin_path("bad/libheun_euler.so"));
  const run_result r = p->run("heun_euler", 1e-6, horizon, times, run_limits{});
  ASSERT_TRUE(r.stop_reason.empty()) << r.stop_reason;
  ASSERT_EQ(r.sample_y.size(), times.size());
  EXPECT_GT(r.steps, 100);
  EXPECT_GT(r.rejected_steps, 0);
  EXPECT_EQ(r.work.force_evals, 2 * (r.steps + r.rejected_steps) + 2);
  double e = 0.0;
  for (std::size_t j = 0; j < times.size(); ++j) e = std::max(e, std::abs(r.sample_y[j][0] - p->exact(times[j])[0]));
  EXPECT_LT(e, 1e-3);  // a local tolerance of 1e-6 over two periods: within 1e-3 rad
  EXPECT_GT(e, 1e-8);  // and not exact: the step is Heun's
  ensure_loaded(plugin_path("bad/libheun_euler_dirty.so"));
  const run_result dirty = p->run("heun_euler_dirty", 1e-6, horizon, times, run_limits{});
  EXPECT_EQ(dirty.sample_y, r.sample_y);
  EXPECT_EQ(dirty.rejected_steps, r.rejected_steps);
  ensure_loaded(plugin_path("bad/libbad_proposal.so"));
  EXPECT_EQ(p->run("bad_proposal", 1e-6, horizon, times, run_limits{}).stop_reason,
            "plugin method bad_proposal proposed a next step of nan at t = 0 (not finite and > 0)");
}

// A step that crashes, under --isolate: the run fails with the signal; this process goes on.
TEST(plugins, a_crash_under_isolate_fails_its_run) {
  set_plugin_isolation(true);
  const run_result crash = run_bad("bad_crash");
  set_plugin_isolation(false);
  EXPECT_NE(crash.stop_reason.find("--isolate: the run crashed: signal 11"), std::string::npos) << crash.stop_reason;
  // A good plugin's run under --isolate comes back whole: the same as in-process.
  ensure_loaded(plugin_path("libruth3.so"));
  const auto p = make_problem("pendulum");
  const auto times = sample_times(p->horizon(), 4);
  const run_result here = p->run("ruth3", 0.01, p->horizon(), times, run_limits{});
  set_plugin_isolation(true);
  const run_result there = p->run("ruth3", 0.01, p->horizon(), times, run_limits{});
  set_plugin_isolation(false);
  EXPECT_EQ(there.sample_y, here.sample_y);
  EXPECT_EQ(there.final_y, here.final_y);
  EXPECT_EQ(there.steps, here.steps);
  EXPECT_EQ(there.work.force_evals, here.work.force_evals);
}

// The loader's validation against garbage: random declared fields, valid and invalid
// names, present and missing functions. validate_plugin_table accepts exactly the tables
// plugin.h allows (an oracle written from its comments), never crashes, and every
// refusal is one line.
int dummy_step(void*, double, double, double*, double*, stepbench_force_fn, void*) { return 0; }
int dummy_try(void*, double, double, double, double*, double*, stepbench_force_fn, void*, double*, int*) { return 0; }
void* dummy_create(int) { return nullptr; }
void dummy_destroy(void*) {}

TEST(plugins, validation_accepts_exactly_what_plugin_h_allows) {
  std::mt19937 rng(34);
  const std::vector<const char*> names{"a",
                                       "ok_name",
                                       "z9_",
                                       "",
                                       "9lead",
                                       "Upper",
                                       "has-dash",
                                       "rk4",
                                       "dup",
                                       "with space",
                                       nullptr,
                                       "abcdefghijabcdefghijabcdefghijabcdefghij",
                                       "abcdefghijabcdefghijabcdefghijabcdefghijk"};
  const std::vector<const char*> good_names{"m", "my_rk4", "ruth3", "x_1", "dup"};
  const std::vector<std::string> taken{"rk4", "euler"};
  const auto pick = [&](auto lo, auto hi) { return std::uniform_int_distribution<long>(lo, hi)(rng); };
  // A field: in its range five times in eight, just outside it or anything else the rest.
  const auto field = [&](int lo, int hi) {
    const long r = pick(0, 7);
    return static_cast<int>(r == 0 ? pick(-1000000, 1000000) : r <= 2 ? pick(lo - 2, hi + 2) : pick(lo, hi));
  };
  int accepted = 0, refused = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<stepbench_method> methods(static_cast<std::size_t>(pick(1, 4)));
    for (auto& m : methods) {
      m.name = pick(0, 1) ? good_names[static_cast<std::size_t>(pick(0, static_cast<long>(good_names.size()) - 1))]
                          : names[static_cast<std::size_t>(pick(0, static_cast<long>(names.size()) - 1))];
      m.description = pick(0, 1) ? "d" : nullptr;
      m.kind = field(0, 1);
      m.order = field(1, 16);
      m.force_evals_per_step = field(1, 64);
      m.symplectic = field(0, 1);
      m.create = pick(0, 7) ? dummy_create : nullptr;
      m.destroy = pick(0, 7) ? dummy_destroy : nullptr;
      // The function its kind needs three times in four, else either, both or none.
      const long f = pick(0, 7);
      const bool fixed = m.kind == STEPBENCH_FIXED_STEP;
      m.step = f < 6 ? (fixed ? dummy_step : nullptr) : pick(0, 1) ? dummy_step : nullptr;
      m.try_step = f < 6 ? (fixed ? nullptr : dummy_try) : pick(0, 1) ? dummy_try : nullptr;
    }
    stepbench_plugin_table table{pick(0, 5) ? STEPBENCH_PLUGIN_ABI_VERSION : static_cast<int>(pick(-3, 5)),
                                 pick(0, 5) ? static_cast<int>(methods.size()) : static_cast<int>(pick(-2, 70)),
                                 pick(0, 20) ? methods.data() : nullptr};
    if (table.method_count > static_cast<int>(methods.size()) && table.method_count <= 64)
      table.method_count = static_cast<int>(methods.size());  // never read past the array
    // The oracle.
    bool ok = table.abi_version == STEPBENCH_PLUGIN_ABI_VERSION && table.method_count >= 1 &&
              table.method_count <= 64 && table.methods != nullptr;
    for (int i = 0; ok && i < table.method_count; ++i) {
      const stepbench_method& m = methods[static_cast<std::size_t>(i)];
      const std::string name = m.name ? m.name : "";
      const bool name_ok = m.name && !name.empty() && name.size() <= 40 && name[0] >= 'a' && name[0] <= 'z' &&
                           name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") == std::string::npos;
      const bool fixed = m.kind == STEPBENCH_FIXED_STEP, adaptive = m.kind == STEPBENCH_ADAPTIVE;
      ok = name_ok && (fixed || adaptive) && m.order >= 1 && m.order <= 16 && m.force_evals_per_step >= 1 &&
           m.force_evals_per_step <= 64 && (m.symplectic == 0 || m.symplectic == 1) && m.create && m.destroy &&
           (fixed ? m.step && !m.try_step : m.try_step && !m.step) &&
           std::find(taken.begin(), taken.end(), name) == taken.end();
      for (int j = 0; ok && j < i; ++j) ok = name != methods[static_cast<std::size_t>(j)].name;
    }
    const std::string e = validate_plugin_table(&table, taken);
    ASSERT_EQ(e.empty(), ok) << "trial " << trial << ": " << e;
    ASSERT_EQ(e.find('\n'), std::string::npos) << e;
    (ok ? accepted : refused) += 1;
  }
  // Both outcomes were exercised, not only refusals.
  EXPECT_GT(accepted, 100);
  EXPECT_GT(refused, 100);
  EXPECT_EQ(validate_plugin_table(nullptr, taken), "stepbench_plugin() returned NULL");
}

}  // namespace
}  // namespace stepbench

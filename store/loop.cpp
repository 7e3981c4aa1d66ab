#include "store/loop.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/number.hpp"
#include "judge/loop.hpp"
#include "store/h5.hpp"
#include "store/schema.hpp"

namespace stepbench {
namespace {

void write_runs(H5::Group& g, const loop_method& m, double step_cost_ns, const std::string& source) {
  const auto& rows = m.rows;
  std::vector<loop_cost> costs;
  for (const auto& r : rows) costs.push_back(cost_verdict(r.config, step_cost_ns, source));
  auto col = [&](auto get) {
    using T = decltype(get(rows.front(), costs.front()));
    std::vector<T> v;
    for (std::size_t i = 0; i < rows.size(); ++i) v.push_back(get(rows[i], costs[i]));
    return v;
  };
  using R = const loop_row&;
  using C = const loop_cost&;
  auto i64 = [](auto x) { return static_cast<std::int64_t>(x); };
  auto i8 = [](bool x) { return static_cast<std::int8_t>(x); };
  auto variable = [](R r) { return r.config.design == loop_design::variable; };
  h5::table t;
  t.add("design", col([](R r, C) { return std::string(to_string(r.config.design)); }));
  t.add("clock", col([](R r, C) { return r.clock; }));
  t.add("display_hz", col([](R r, C) { return r.config.display_hz; }));
  t.add("physics_hz", col([&](R r, C) { return variable(r) ? nan : r.config.physics_hz; }));
  t.add("dt", col([&](R r, C) { return uses_accumulator(r.config.design) ? r.config.dt() : nan; }));
  t.add("substeps",
        col([&](R r, C) { return i64(r.config.design == loop_design::substeps ? r.config.substeps() : 0); }));
  t.add("clamp_s", col([](R r, C) { return r.config.clamp_s; }));
  t.add("jitter_seed", col([&](R r, C) { return r.config.jitter_seed ? i64(*r.config.jitter_seed) : i64(-1); }));
  t.add("stall_at_s", col([](R r, C) { return r.config.stall_at_s; }));
  t.add("frames", col([&](R r, C) { return i64(r.frames); }));
  t.add("physics_steps", col([&](R r, C) { return i64(r.physics_steps); }));
  t.add("force_evals", col([&](R r, C) { return i64(r.force_evals); }));
  t.add("shown_err_max", col([](R r, C) { return r.shown_err_max; }));
  t.add("shown_err_rms", col([](R r, C) { return r.shown_err_rms; }));
  t.add("final_shown_err", col([](R r, C) { return r.final_shown_err; }));
  t.add("clock_dependence", col([](R r, C) { return r.clock_dependence; }));
  t.add("physics_clock_dependence", col([](R r, C) { return r.physics_clock_dependence; }));
  t.add("judder", col([](R r, C) { return r.judder; }));
  t.add("lag_s", col([](R r, C) { return r.lag_s; }));
  t.add("lag_clock_s", col([](R r, C) { return r.lag_clock_s; }));
  t.add("steps_per_frame_mean", col([](R r, C) { return r.steps_per_frame_mean; }));
  t.add("steps_per_frame_max", col([&](R r, C) { return i64(r.steps_per_frame_max); }));
  t.add("stall_burst_steps", col([&](R r, C) { return i64(r.stall_burst_steps); }));
  t.add("clamp_hits", col([&](R r, C) { return i64(r.clamp_hits); }));
  t.add("alpha_min", col([](R r, C) { return r.alpha_min; }));
  t.add("alpha_max", col([](R r, C) { return r.alpha_max; }));
  t.add("physics_t", col([](R r, C) { return r.physics_t; }));
  t.add("diverged", col([&](R r, C) { return i8(r.diverged); }));
  t.add("note", col([](R r, C) { return r.note; }));
  t.add("step_cost_ns", col([](R, C c) { return c.step_cost_ns; }));
  t.add("frame_budget_ns", col([](R, C c) { return c.schedule.frame_budget_s * 1e9; }));
  t.add("worst_frame_work_ns", col([](R, C c) { return c.schedule.worst_work_s * 1e9; }));
  t.add("late_frames", col([&](R, C c) { return i64(c.schedule.late_frames); }));
  t.add("physics_load", col([](R, C c) { return c.schedule.load; }));
  t.add("outcome", col([](R, C c) { return std::string(to_string(c.schedule.outcome)); }));
  t.add("outcome_without_clamp", col([](R, C c) { return std::string(to_string(c.without_clamp)); }));
  t.add("clamp_prevented_spiral", col([&](R, C c) { return i8(c.clamp_prevented_spiral); }));
  t.write(g, "runs", schema::find("loop_runs"));
  std::vector<std::vector<double>> finals;
  for (const auto& r : rows) finals.push_back(r.final_physics);
  h5::dataset(g, "final_physics_state", finals);
}

void write_cheapest(H5::Group& g, const loop_method& m, const loop_options& opts) {
  const auto rows = cheapest_designs(m, opts);
  h5::table t;
  auto col = [&](auto get) {
    using T = decltype(get(rows.front()));
    std::vector<T> v;
    for (const auto& r : rows) v.push_back(get(r));
    return v;
  };
  t.add("display_hz", col([](const loop_cheapest& c) { return c.display_hz; }));
  t.add("target", col([](const loop_cheapest& c) { return c.target; }));
  t.add("found", col([](const loop_cheapest& c) { return static_cast<std::int8_t>(c.found); }));
  t.add("design", col([](const loop_cheapest& c) { return c.design; }));
  t.add("physics_hz", col([](const loop_cheapest& c) { return c.physics_hz; }));
  t.add("steps_per_frame_mean", col([](const loop_cheapest& c) { return c.steps_per_frame_mean; }));
  t.add("shown_err_max", col([](const loop_cheapest& c) { return c.shown_err_max; }));
  t.write(g, "cheapest", schema::find("loop_cheapest"));
}

}  // namespace

void write_loop(H5::Group& root, const study& s) {
  const loop_study& ls = s.results.get<loop_study>();
  if (ls.problems.empty()) return;
  const loop_options& o = ls.options;
  H5::Group top = root.createGroup("loop");
  std::string designs;
  for (loop_design d : all_loop_designs) designs += (designs.empty() ? "" : ",") + std::string(to_string(d));
  h5::attr(top, "designs", designs);
  h5::attr(top, "display_hz", o.display_hz);
  h5::attr(top, "physics_hz", o.physics_hz);
  h5::attr(top, "reference_display_hz", o.reference_display_hz);
  h5::attr(top, "clamp_s", o.clamp_s);
  h5::attr(top, "stall_s", o.stall_s);
  h5::attr(top, "stall_at_fraction", o.stall_at_fraction);
  h5::attr(top, "jitter", o.jitter);
  h5::attr(top, "jitter_seed", static_cast<long>(o.jitter_seed));
  h5::attr(
      top, "jitter_distribution",
      "interval = (1 + jitter (2u - 1)) / display_hz, u = (x >> 11) 2^-53, x the outputs of std::mt19937_64(seed)");
  h5::attr(top, "accumulator_slack", accumulator_slack);
  h5::attr(top, "target", o.target);
  h5::attr(top, "stated_step_cost_ns", o.stated_step_cost_ns);
  h5::attr(top, "spiral_factor", spiral_factor);
  h5::attr(top, "settle_frames", settle_frames);
  h5::attr(top, "wall_seconds", ls.wall_seconds);
  for (const auto& lp : ls.problems) {
    H5::Group pg = top.createGroup(lp.name);
    h5::attr(pg, "position_unit", lp.position_unit);
    h5::attr(pg, "horizon", lp.horizon);
    h5::attr(pg, "truth_source", lp.truth_source);
    const problem_study* ps = nullptr;
    for (const auto& p : s.problems)
      if (p.problem->name() == lp.name) ps = &p;
    for (const auto& m : lp.methods) {
      H5::Group mg = pg.createGroup(m.info.name);
      const double measured = ps && s.timed ? measured_step_cost_ns(*ps, m.info.name) : nan;
      const bool is_measured = std::isfinite(measured) && measured > 0.0;
      const double cost = is_measured ? measured : o.stated_step_cost_ns;
      const std::string source = is_measured ? "measured" : "stated";
      h5::attr(mg, "step_cost_ns", cost);
      h5::attr(mg, "step_cost_source", source);
      write_runs(mg, m, cost, source);
      write_cheapest(mg, m, o);
    }
  }
}

}  // namespace stepbench

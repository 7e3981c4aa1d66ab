#include "store/loop.hpp"

#include <cmath>

#include "core/number.hpp"
#include "judge/loop.hpp"
#include "store/columns.hpp"

namespace stepbench {
namespace {

// A row of a loop's runs table: the run and its cost verdict.
struct loop_run {
  loop_row row;
  loop_cost cost;
};

const auto loop_run_columns =
    column_map<loop_run>("loop_runs", "/loop/<p>/<m>/runs")
        .derived("design", [](const loop_run& r) { return to_string(r.row.config.design); })
        .member("clock", &loop_run::row, &loop_row::clock)
        .member("display_hz", &loop_run::row, &loop_row::config, &loop_config::display_hz)
        .derived("physics_hz",
                 [](const loop_run& r) {
                   return r.row.config.design == loop_design::variable ? nan : r.row.config.physics_hz;
                 })
        .derived("dt",
                 [](const loop_run& r) { return uses_accumulator(r.row.config.design) ? r.row.config.dt() : nan; })
        .derived("substeps",
                 [](const loop_run& r) {
                   return r.row.config.design == loop_design::substeps ? r.row.config.substeps() : 0;
                 })
        .member("clamp_s", &loop_run::row, &loop_row::config, &loop_config::clamp_s)
        .derived("jitter_seed",
                 [](const loop_run& r) {
                   return r.row.config.jitter_seed ? static_cast<long>(*r.row.config.jitter_seed) : -1L;
                 })
        .member("stall_at_s", &loop_run::row, &loop_row::config, &loop_config::stall_at_s)
        .member("frames", &loop_run::row, &loop_row::frames)
        .member("physics_steps", &loop_run::row, &loop_row::physics_steps)
        .member("force_evals", &loop_run::row, &loop_row::force_evals)
        .member("shown_err_max", &loop_run::row, &loop_row::shown_err_max)
        .member("shown_err_rms", &loop_run::row, &loop_row::shown_err_rms)
        .member("final_shown_err", &loop_run::row, &loop_row::final_shown_err)
        .member("clock_dependence", &loop_run::row, &loop_row::clock_dependence)
        .member("physics_clock_dependence", &loop_run::row, &loop_row::physics_clock_dependence)
        .member("judder", &loop_run::row, &loop_row::judder)
        .member("lag_s", &loop_run::row, &loop_row::lag_s)
        .member("lag_clock_s", &loop_run::row, &loop_row::lag_clock_s)
        .member("steps_per_frame_mean", &loop_run::row, &loop_row::steps_per_frame_mean)
        .member("steps_per_frame_max", &loop_run::row, &loop_row::steps_per_frame_max)
        .member("stall_burst_steps", &loop_run::row, &loop_row::stall_burst_steps)
        .member("clamp_hits", &loop_run::row, &loop_row::clamp_hits)
        .member("alpha_min", &loop_run::row, &loop_row::alpha_min)
        .member("alpha_max", &loop_run::row, &loop_row::alpha_max)
        .member("physics_t", &loop_run::row, &loop_row::physics_t)
        .member("diverged", &loop_run::row, &loop_row::diverged)
        .member("note", &loop_run::row, &loop_row::note)
        .member("step_cost_ns", &loop_run::cost, &loop_cost::step_cost_ns)
        .derived("frame_budget_ns", [](const loop_run& r) { return r.cost.schedule.frame_budget_s * 1e9; })
        .derived("worst_frame_work_ns", [](const loop_run& r) { return r.cost.schedule.worst_work_s * 1e9; })
        .member("late_frames", &loop_run::cost, &loop_cost::schedule, &loop_schedule::late_frames)
        .member("physics_load", &loop_run::cost, &loop_cost::schedule, &loop_schedule::load)
        .derived("outcome", [](const loop_run& r) { return to_string(r.cost.schedule.outcome); })
        .derived("outcome_without_clamp", [](const loop_run& r) { return to_string(r.cost.without_clamp); })
        .member("clamp_prevented_spiral", &loop_run::cost, &loop_cost::clamp_prevented_spiral);

const auto loop_cheapest_columns = column_map<loop_cheapest>("loop_cheapest", "/loop/<p>/<m>/cheapest")
                                       .member("display_hz", &loop_cheapest::display_hz)
                                       .member("target", &loop_cheapest::target)
                                       .member("found", &loop_cheapest::found)
                                       .member("design", &loop_cheapest::design)
                                       .member("physics_hz", &loop_cheapest::physics_hz)
                                       .member("steps_per_frame_mean", &loop_cheapest::steps_per_frame_mean)
                                       .member("shown_err_max", &loop_cheapest::shown_err_max);

}  // namespace

std::vector<schema::table> loop_tables() { return {loop_run_columns.spec(), loop_cheapest_columns.spec()}; }

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
      if (p.name == lp.name) ps = &p;
    for (const auto& m : lp.methods) {
      H5::Group mg = pg.createGroup(m.info.name);
      const double measured = ps && s.timed ? measured_step_cost_ns(*ps, m.info.name) : nan;
      const bool is_measured = std::isfinite(measured) && measured > 0.0;
      const double cost = is_measured ? measured : o.stated_step_cost_ns;
      const std::string source = is_measured ? "measured" : "stated";
      h5::attr(mg, "step_cost_ns", cost);
      h5::attr(mg, "step_cost_source", source);
      std::vector<loop_run> rows;
      std::vector<std::vector<double>> finals;
      for (const auto& r : m.rows) {
        rows.push_back({r, cost_verdict(r.config, cost, source)});
        finals.push_back(r.final_physics);
      }
      loop_run_columns.write(mg, "runs", rows);
      h5::dataset(mg, "final_physics_state", finals);
      loop_cheapest_columns.write(mg, "cheapest", cheapest_designs(m, o));
    }
  }
}

}  // namespace stepbench

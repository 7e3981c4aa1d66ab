// `stepbench scan` (study/scan.hpp): its axes and their refusals, the grid, and the map
// against the theory: on the stiff spring (k_s 1e1 .. 1e7 N/m, log) at one step a 60 Hz
// frame, each explicit method's stable/unstable boundary lies within one grid cell of
// its oscillator stability limit, w dt = 2 sqrt(2) for RK4 and 2 for semi-implicit Euler
// (Hairer & Wanner, "Solving ODEs II", sec. IV.2; the study computes the same limits
// from the compiled steps, study/stability.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>

#include "core/measure.hpp"
#include "judge/scan.hpp"
#include "parts/study.hpp"
#include "registry/registry.hpp"
#include "render/scan.hpp"
#include "run/scan.hpp"
#include "run/sweep.hpp"
#include "store/scan.hpp"
#include "store/study_file.hpp"
#include "study/scan.hpp"

using namespace stepbench;

namespace {

void expect_refused(const std::string& text, const std::string& problem, const std::string& fragment) {
  try {
    parse_scan_axis(text, problem);
    ADD_FAILURE() << text << " was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
  }
}

}  // namespace

TEST(scan, axes_parse_and_refuse) {
  const scan_axis a = parse_scan_axis("stiff_spring.k_s=1e1:1e7:25:log", "stiff_spring");
  EXPECT_EQ(a.param, "k_s");
  EXPECT_TRUE(a.log);
  const auto v = a.values();
  ASSERT_EQ(v.size(), 25u);
  EXPECT_EQ(v.front(), 10.0);
  EXPECT_EQ(v.back(), 1e7);
  EXPECT_NEAR(v[4], 100.0, 1e-9);  // four steps of 10^(1/4): one decade
  const auto lin = parse_scan_axis("pendulum.theta0_deg=1:179.9:3", "pendulum").values();
  EXPECT_EQ(lin, (std::vector<double>{1.0, 90.45, 179.9}));
  expect_refused("stiff_spring.k_s=-1:10:5", "stiff_spring", "outside the parameter's range");
  expect_refused("pendulum.theta0_deg=1:180:5", "pendulum", "outside the parameter's range");
  expect_refused("stiff_spring.stiffness=1:10:5", "stiff_spring", "has no parameter 'stiffness'");
  expect_refused("pendulum.theta0_deg=1:10:5", "stiff_spring", "not pendulum");
  expect_refused("stiff_spring.k_s=1:10:0", "stiff_spring", "count");
  expect_refused("stiff_spring.k_s=1:10", "stiff_spring", "malformed");
  expect_refused("stiff_spring.k_s=10:1:5", "stiff_spring", "lo must be below hi");
  expect_refused("stiff_spring.k_d=0:10:5:log", "stiff_spring", "log axis needs lo > 0");
  expect_refused("spring_chain.masses=2.5:10:4", "spring_chain", "must be a whole number");
  expect_refused("spring_chain.masses=2:4:5", "spring_chain", "repeats");
  // A whole-numbered parameter on a log axis: rounded, so 8 .. 4096 in 10 points doubles.
  const auto masses = parse_scan_axis("spring_chain.masses=8:4096:10:log", "spring_chain").values();
  for (std::size_t i = 0; i < masses.size(); ++i) EXPECT_EQ(masses[i], 8.0 * std::ldexp(1.0, static_cast<int>(i)));
}

TEST(scan, grid_varies_the_first_axis_slowest) {
  const auto grid = scan_grid({{"a", 1, 2, 2, false, false}, {"b", 10, 30, 3, false, false}});
  ASSERT_EQ(grid.size(), 6u);
  EXPECT_EQ(grid[0], (std::vector<double>{1, 10}));
  EXPECT_EQ(grid[2], (std::vector<double>{1, 30}));
  EXPECT_EQ(grid[3], (std::vector<double>{2, 10}));
}

TEST(scan, stiff_spring_boundary_follows_the_stability_limit) {
  scan_options o;
  o.problem = "stiff_spring";
  o.axes = {parse_scan_axis("stiff_spring.k_s=1e1:1e7:25:log", "stiff_spring")};
  o.hz = {60};
  o.substeps = {1};
  o.methods = {"rk4", "semi_implicit_euler", "implicit_euler"};
  const scan_result s = run_scan(o);
  ASSERT_EQ(s.points.size(), 25u);
  const double dt = 1.0 / 60.0, cell = std::sqrt(std::pow(10.0, 0.25));  // one cell in w = sqrt(k_s / m)
  for (const auto& [method, limit] : {std::pair{"rk4", 2.0 * std::numbers::sqrt2}, {"semi_implicit_euler", 2.0}}) {
    double last_stable = 0.0, first_unstable = 0.0;
    for (const auto& r : s.runs) {
      if (r.method != method) continue;
      const double w_dt = std::sqrt(s.points[r.point].values[0]) * dt;
      if (r.row.metrics.completed() && first_unstable == 0.0) last_stable = w_dt;
      if (r.row.metrics.diverged && first_unstable == 0.0) first_unstable = w_dt;
      // Unstable once, unstable above: the map has one boundary.
      if (first_unstable > 0.0) {
        EXPECT_TRUE(r.row.metrics.diverged) << method << " at w dt " << w_dt;
      }
    }
    ASSERT_GT(last_stable, 0.0) << method;
    ASSERT_GT(first_unstable, 0.0) << method;
    EXPECT_NEAR(first_unstable / last_stable, cell, 1e-9) << method << ": the boundary lies between neighbours";
    EXPECT_LE(last_stable, limit * cell) << method;
    EXPECT_GE(first_unstable, limit / cell) << method;
  }
  // Implicit Euler is stable at every stiffness; the answer says so, and names RK4's break.
  const scan_answer a = answer_scan(s, 1.0);  // 1 m: any stable run meets it
  for (const auto& b : a.breaks) {
    if (b.method == "implicit_euler") {
      EXPECT_EQ(b.where, "stable everywhere");
    } else if (b.method == "rk4") {
      EXPECT_NE(b.where.find("diverges for k_s >= "), std::string::npos) << b.where;
    }
  }
  ASSERT_EQ(a.choices.size(), 1u);
  EXPECT_EQ(a.choices[0].method, "implicit_euler");
}

TEST(scan, written_and_read_back) {
  scan_options o;
  o.problem = "pendulum";
  o.axes = {parse_scan_axis("pendulum.theta0_deg=10:170:3", "pendulum")};
  o.hz = {30, 60};
  o.substeps = {1, 4};
  o.methods = {"rk4", "velocity_verlet"};
  study s;
  s.options.parts = {"scans"};
  const auto& scans = s.results.put(std::vector<scan_result>{run_scan(o)});
  judge_study(s);
  const auto path = (std::filesystem::temp_directory_path() / "stepbench_test_scan.h5").string();
  write_study(s, path);
  const scan_result back = read_scan(path, "");
  std::filesystem::remove(path);
  EXPECT_EQ(back.options.substeps, o.substeps);  // the file's counts, not the defaults and them
  ASSERT_EQ(back.points.size(), 3u);
  ASSERT_EQ(back.runs.size(), scans[0].runs.size());
  for (std::size_t i = 0; i < back.runs.size(); ++i) {
    const auto &x = back.runs[i].row.metrics, &y = scans[0].runs[i].row.metrics;
    EXPECT_TRUE(x.err_pos_max == y.err_pos_max || (std::isnan(x.err_pos_max) && std::isnan(y.err_pos_max)));
    EXPECT_EQ(back.runs[i].row.work.force_evals, scans[0].runs[i].row.work.force_evals);
  }
  // The pendulum has a closed form: every point is trusted, and its answer is the same read back.
  for (const auto& p : back.points) EXPECT_EQ(p.truth_source, "closed_form");
  EXPECT_EQ(format_scan_answer(answer_scan(back, 1e-3)), format_scan_answer(answer_scan(scans[0], 1e-3)));
}

// A scan in three shards, merged, equals the unsharded scan in every accuracy field; the
// shards partition the grid; a shard twice, or one missing, is refused (issue 20).
TEST(scan, shards_merge_to_the_unsharded_scan) {
  scan_options o;
  o.problem = "spring_chain";
  o.axes = {parse_scan_axis("spring_chain.masses=4:16:3:log", "spring_chain"),
            parse_scan_axis("spring_chain.k_s=1e2:1e4:3:log", "spring_chain")};
  o.hz = {60};
  o.substeps = {1, 8};
  o.methods = {"semi_implicit_euler", "rk4"};
  const scan_result whole = run_scan(o);
  std::vector<scan_result> shards;
  std::vector<std::size_t> seen;
  for (int k = 0; k < 3; ++k) {
    scan_options part = o;
    part.shard_index = k;
    part.shard_count = 3;
    shards.push_back(run_scan(part));
    for (const auto& p : shards.back().points) seen.push_back(p.index);
  }
  std::sort(seen.begin(), seen.end());
  ASSERT_EQ(seen.size(), 9u);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i) << "each point in exactly one shard";
  // Balanced by size, the references' predicted work most of it (it grows as masses^1.5
  // k_s^0.5): the stiffest 16-mass rope, the largest by far, has a shard to itself.
  std::size_t alone = 0;
  for (const auto& s : shards)
    for (const auto& p : s.points)
      if (p.values == std::vector<double>{16, 1e4}) alone += s.points.size() == 1;
  EXPECT_EQ(alone, 1u);
  std::vector<std::size_t> missing;
  const scan_result merged = merge_scans({shards[2], shards[0], shards[1]}, false, missing);
  EXPECT_TRUE(missing.empty());
  ASSERT_EQ(merged.points.size(), whole.points.size());
  ASSERT_EQ(merged.runs.size(), whole.runs.size());
  for (std::size_t i = 0; i < merged.points.size(); ++i) {
    EXPECT_EQ(merged.points[i].index, whole.points[i].index);
    EXPECT_EQ(merged.points[i].values, whole.points[i].values);
    EXPECT_EQ(merged.points[i].truth_source, whole.points[i].truth_source);
  }
  const auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  for (std::size_t i = 0; i < merged.runs.size(); ++i) {
    const auto &a = merged.runs[i], &b = whole.runs[i];
    EXPECT_EQ(a.point, b.point);
    EXPECT_EQ(a.method, b.method);
    EXPECT_EQ(a.substeps, b.substeps);
    EXPECT_TRUE(same(a.row.metrics.err_pos_max, b.row.metrics.err_pos_max)) << i;
    EXPECT_TRUE(same(a.row.metrics.err_pos_final, b.row.metrics.err_pos_final)) << i;
    EXPECT_EQ(a.row.metrics.diverged, b.row.metrics.diverged);
    EXPECT_EQ(a.row.work.force_evals, b.row.work.force_evals);
    EXPECT_EQ(a.row.steps, b.row.steps);
  }
  EXPECT_EQ(format_scan_answer(answer_scan(merged, 1e-3)), format_scan_answer(answer_scan(whole, 1e-3)));
  // Refusals: a shard twice; a shard missing (unless partial, which says what is missing).
  EXPECT_THROW(merge_scans({shards[0], shards[1], shards[0]}, false, missing), std::invalid_argument);
  EXPECT_THROW(merge_scans({shards[0], shards[1]}, false, missing), std::invalid_argument);
  const scan_result part = merge_scans({shards[0], shards[1]}, true, missing);
  EXPECT_EQ(missing.size(), shards[2].points.size());
  EXPECT_EQ(part.points.size() + missing.size(), 9u);
  // Shards of different scans.
  scan_options other = o;
  other.tol = 1e-4;
  other.shard_index = 2;
  other.shard_count = 3;
  EXPECT_THROW(merge_scans({shards[0], shards[1], run_scan(other)}, false, missing), std::invalid_argument);
}

namespace {

// A small stiff-spring scan: k_s 10 .. 1000 N/m (3 points, log) at 60 Hz, one step a frame.
scan_options small_spring_scan() {
  scan_options o;
  o.problem = "stiff_spring";
  o.axes = {parse_scan_axis("stiff_spring.k_s=1e1:1e3:3:log", "stiff_spring")};
  o.hz = {60};
  o.substeps = {1};
  o.methods = {"rk4"};
  return o;
}

// The scan written alone to a study file and read back, as a shard file meets `merge`.
scan_result through_file(const scan_result& scan, const std::string& file) {
  // The process id keeps test processes run at once apart.
  const auto path = (std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + file)).string();
  study s;
  s.options.parts = {"scans"};
  s.results.put(std::vector<scan_result>{scan});
  judge_study(s);
  write_study(s, path);
  scan_result back = read_scan(path, "");
  std::filesystem::remove(path);
  return back;
}

std::string merge_refusal(const std::vector<scan_result>& shards) {
  std::vector<std::size_t> missing;
  try {
    merge_scans(shards, false, missing);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(merged)";
}

}  // namespace

// What makes shards one scan is written and read back, and merge compares all of it: shards
// run with another --set, other methods, other reference tolerances or another work budget
// are refused in one line naming the difference and both values; the merged scan's wall
// time is the sum of its shards' (issue 20 review).
TEST(scan, merge_refuses_shards_of_other_options_read_from_files) {
  scan_options o = small_spring_scan();
  o.shard_count = 2;
  o.fixed = {{"mass_kg", 2.0}};
  o.ref_tol = {1e-12, 1e-13};
  o.limits.work_budget = 1e7;
  const scan_result first = through_file(run_scan(o), "stepbench_test_shard1.h5");
  EXPECT_EQ(first.options.fixed, (std::map<std::string, double>{{"mass_kg", 2.0}}));
  EXPECT_EQ(first.options.methods, (std::vector<std::string>{"rk4"}));
  EXPECT_EQ(first.options.ref_tol.rtol, 1e-12);
  EXPECT_EQ(first.options.ref_tol.atol, 1e-13);
  EXPECT_EQ(first.options.limits.work_budget, 1e7);
  EXPECT_GT(first.wall_seconds, 0.0);
  o.shard_index = 1;
  const scan_result second = through_file(run_scan(o), "stepbench_test_shard2.h5");
  std::vector<std::size_t> missing;
  const scan_result merged = merge_scans({first, second}, false, missing);
  EXPECT_EQ(merged.points.size(), 3u);
  EXPECT_DOUBLE_EQ(merged.wall_seconds, first.wall_seconds + second.wall_seconds);

  const auto refused = [&](const scan_options& other, const std::string& fragment) {
    const std::string why = merge_refusal({first, through_file(run_scan(other), "stepbench_test_other.h5")});
    EXPECT_NE(why.find(fragment), std::string::npos) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << "one line: " << why;
  };
  scan_options unset = o;
  unset.fixed.clear();
  refused(unset, "the shards differ in their fixed parameters (--set): ");
  refused(unset, "has mass_kg=2, ");
  refused(unset, "stepbench_test_other.h5' has none");
  scan_options heavier = o;
  heavier.fixed["mass_kg"] = 3.0;
  refused(heavier, "has mass_kg=3");
  scan_options methods = o;
  methods.methods = {"rk4", "velocity_verlet"};
  refused(methods, "the shards differ in their methods: ");
  refused(methods, "has rk4,velocity_verlet");
  scan_options tolerances = o;
  tolerances.ref_tol.rtol = 1e-11;
  refused(tolerances, "the shards differ in their reference tolerances: ");
  scan_options budget = o;
  budget.limits.work_budget = 2e7;
  refused(budget, "the shards differ in their work budget: ");
}

// A shard with no point (more shards than grid points) is written, read back with empty
// tables, and merges with the others into the whole scan.
TEST(scan, an_empty_shard_is_written_read_and_merged) {
  scan_options o = small_spring_scan();
  o.shard_count = 4;  // 3 points: the fourth shard holds none
  std::vector<scan_result> shards;
  for (int k = 0; k < 4; ++k) {
    o.shard_index = k;
    shards.push_back(through_file(run_scan(o), "stepbench_test_shard" + std::to_string(k) + ".h5"));
  }
  const scan_result& empty = shards[3];
  EXPECT_TRUE(empty.points.empty());
  EXPECT_TRUE(empty.runs.empty());
  EXPECT_EQ(empty.grid_points, 3u);
  EXPECT_EQ(empty.options.shard_index, 3);
  std::vector<std::size_t> missing;
  const scan_result merged = merge_scans(shards, false, missing);
  EXPECT_TRUE(missing.empty());
  ASSERT_EQ(merged.points.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(merged.points[i].index, i);
  const scan_result whole = run_scan(small_spring_scan());
  ASSERT_EQ(merged.runs.size(), whole.runs.size());
  for (std::size_t i = 0; i < merged.runs.size(); ++i)
    EXPECT_EQ(merged.runs[i].row.metrics.err_pos_max, whole.runs[i].row.metrics.err_pos_max) << i;
}

// A run whose work (steps x force evaluations a step x coordinates) would exceed the work
// budget is recorded as skipped, with the estimate, not run: rk4 takes 4 evaluations a
// step, so with a budget of three times one step a frame's, 2 substeps run and 4 do not;
// 2^20 substeps (134 million evaluations) are over the default budget of 2^25.
TEST(scan, runs_over_the_work_budget_are_skipped) {
  scan_options o = small_spring_scan();
  o.axes = {parse_scan_axis("stiff_spring.k_s=1e2:1e2:1", "stiff_spring")};
  const long one_step_a_frame = run_scan(o).runs.at(0).row.work.force_evals;
  EXPECT_EQ(one_step_a_frame, 32 * 4);  // 32 frames of 60 Hz in the horizon
  o.substeps = {1, 2, 4, 1 << 20};
  o.limits.work_budget = 3.0 * static_cast<double>(one_step_a_frame);
  const scan_result s = run_scan(o);
  ASSERT_EQ(s.runs.size(), 4u);
  EXPECT_TRUE(s.runs[0].row.metrics.completed());
  EXPECT_EQ(s.runs[1].row.work.force_evals, 2 * one_step_a_frame);
  EXPECT_TRUE(s.runs[1].row.metrics.completed());
  for (std::size_t i : {2u, 3u}) {
    const auto& r = s.runs[i].row;
    EXPECT_TRUE(r.metrics.skipped) << i;
    EXPECT_EQ(r.steps, 0) << i;
    EXPECT_EQ(r.work.force_evals, 0) << i;
    EXPECT_TRUE(std::isnan(r.metrics.err_pos_max)) << i;
    EXPECT_NE(r.metrics.note.find("exceed the work budget of 384"), std::string::npos) << r.metrics.note;
  }
  EXPECT_NE(s.runs[2].row.metrics.note.find("about 128 steps x 4 force evaluations x 1 coordinates"), std::string::npos)
      << s.runs[2].row.metrics.note;
  // The default budget: 2^20 substeps are skipped; the answer does not count them as stable.
  scan_options huge = small_spring_scan();
  huge.substeps = {1 << 20};
  const scan_result h = run_scan(huge);
  ASSERT_EQ(h.runs.size(), 3u);
  for (const auto& r : h.runs) EXPECT_TRUE(r.row.metrics.skipped);
  const scan_answer ha = answer_scan(h, 1.0);
  EXPECT_EQ(ha.choices.at(0).method, "");
  // Nor is a method skipped at every point "stable everywhere" at one step a frame.
  scan_options one = small_spring_scan();
  one.substeps = {1};
  one.limits.work_budget = 1.0;  // below one step: every run skipped
  const scan_answer oa = answer_scan(run_scan(one), 1.0);
  ASSERT_FALSE(oa.breaks.empty());
  for (const auto& b : oa.breaks) EXPECT_EQ(b.where, "not run: over the work budget at every point") << b.method;
}

// Progress must never end a scan: a report that throws (stderr closed) is dropped, and
// every point is still run.
TEST(scan, a_failing_progress_report_does_not_end_the_scan) {
  scan_options o = small_spring_scan();
  o.jobs = 2;
  int reports = 0;
  o.on_progress = [&](std::size_t, std::size_t) {
    ++reports;
    throw std::runtime_error("stderr is closed");
  };
  const scan_result s = run_scan(o);
  EXPECT_EQ(reports, 3);
  EXPECT_EQ(s.points.size(), 3u);
  EXPECT_EQ(s.runs.size(), 3u);
}

// The references' predicted work (core/measure.hpp): first-order coordinates x w_max T,
// w_max the Gershgorin bound of dF/dx / m. On the rope at rest length, a middle mass's
// row of dF/dx along the rope is -2 k_s on the diagonal and k_s to each neighbour, so the
// bound is sqrt(4 k_s / m) = 2 sqrt(k_s / m) exactly (a chain's highest mode is just below it).
TEST(scan, the_references_predicted_work_is_coordinates_times_w_max_t) {
  auto p = make_problem("spring_chain");
  p->set("masses", 64);
  p->set("k_s", 1e4);
  const double m = 1.0 / 64.0, w = 2.0 * std::sqrt(1e4 / m);
  EXPECT_NEAR(p->fastest_frequency(), w, 1e-9 * w);
  EXPECT_NEAR(predicted_reference_work(*p, 0.5), 2.0 * 192 * w * 0.5, 1e-9 * 192 * w);
  // No Jacobian, a period: w = 2 pi / period; neither: at least one radian.
  auto pendulum = make_problem("pendulum");
  ASSERT_TRUE(std::isfinite(pendulum->period()));
  EXPECT_NEAR(predicted_reference_work(*pendulum, 3.0),
              2.0 * pendulum->dim() * std::max(1.0, 2.0 * std::numbers::pi / pendulum->period() * 3.0), 1e-12);
}

// Over the reference budget the references are not run: the point has no trusted truth
// and says why, and its runs are judged on stability alone. Stability needs no truth: the
// runs that diverge with the references' truth are those that diverge without it, and
// every other run completes (none "failed" for the missing truth).
TEST(scan, over_the_reference_budget_a_point_is_judged_on_stability) {
  scan_options o;
  o.problem = "spring_chain";
  o.axes = {parse_scan_axis("spring_chain.masses=8:64:2:log", "spring_chain"),
            parse_scan_axis("spring_chain.k_s=1e2:1e4:2:log", "spring_chain")};
  o.hz = {60};
  o.substeps = {1, 4};
  o.reference_budget = std::numeric_limits<double>::infinity();
  const scan_result with = run_scan(o);
  o.reference_budget = 1.0;
  const scan_result without = run_scan(o);
  ASSERT_EQ(with.runs.size(), without.runs.size());
  for (const auto& p : with.points) EXPECT_TRUE(p.trusted) << p.note;
  std::size_t diverged = 0, completed = 0;
  for (const auto& p : without.points) {
    EXPECT_FALSE(p.trusted);
    EXPECT_EQ(p.truth_source, "none");
    EXPECT_EQ(p.note.rfind("references not run: their predicted work", 0), 0u) << p.note;
    EXPECT_NE(p.note.find("over the reference budget of 1"), std::string::npos) << p.note;
  }
  for (std::size_t i = 0; i < with.runs.size(); ++i) {
    const auto &a = with.runs[i].row.metrics, &b = without.runs[i].row.metrics;
    ASSERT_EQ(with.runs[i].method, without.runs[i].method);
    EXPECT_EQ(a.diverged, b.diverged) << without.runs[i].method << " at point " << with.runs[i].point << ": " << a.note
                                      << " / " << b.note;
    EXPECT_FALSE(b.failed) << b.note;
    if (b.completed()) {
      ++completed;
      EXPECT_TRUE(std::isnan(b.err_pos_max));
      EXPECT_EQ(b.note, "completed; no trusted truth at this point to measure its error");
    }
    diverged += b.diverged;
  }
  EXPECT_GT(diverged, 0u);  // euler at one step a 60 Hz frame on the stiffer ropes
  EXPECT_GT(completed, 0u);
  // The answer: stability over every point, no tolerance claim without a truth.
  const scan_answer a = answer_scan(without, 1.0);
  EXPECT_EQ(a.untrusted, 4u);
  for (const auto& c : a.choices) EXPECT_EQ(c.method, "") << "nothing is within a tolerance without a truth";
  const scan_answer b = answer_scan(with, 1.0);
  ASSERT_EQ(a.breaks.size(), b.breaks.size());
  for (std::size_t i = 0; i < a.breaks.size(); ++i)
    EXPECT_EQ(a.breaks[i].where, b.breaks[i].where) << a.breaks[i].method;
  EXPECT_NE(format_scan_answer(a).find("4 of 4 points have no trusted truth: their runs are judged on stability alone"),
            std::string::npos)
      << format_scan_answer(a);
}

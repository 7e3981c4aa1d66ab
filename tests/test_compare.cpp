// `stepbench compare`: the decisions (what regresses, what improves, what is noise) on
// small studies written to temporary files and changed one figure at a time, either in
// the file (a field of one `runs` row rewritten with the HDF5 API) or in the study before
// it is written.
#include <H5Cpp.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "judge/compare.hpp"
#include "parts/study.hpp"
#include "render/compare_render.hpp"
#include "render/table_render.hpp"
#include "run/sweep.hpp"
#include "store/study_file.hpp"
#include "study/stability.hpp"

using namespace stepbench;
namespace fs = std::filesystem;

namespace {

// A few methods on one or two problems, 5 levels: milliseconds. The sweep alone (what
// compare reads but /stability, which takes a second and is asked for where it is read).
study small_study(std::vector<std::string> problems = {"damped_spring"},
                  std::vector<std::string> methods = {"rk4", "euler", "velocity_verlet", "gsl_rk4", "rk45"},
                  int levels = 5, std::vector<std::string> parts = {"sweep"}) {
  sweep_options o;
  o.parts = std::move(parts);
  o.problems = std::move(problems);
  o.methods = std::move(methods);
  o.levels = o.max_levels = levels;  // a ladder of exactly `levels` rows
  o.tolerances = tolerance_ladder(true);
  return run_sweep(o);
}

method_study& method(study& s, const std::string& problem, const std::string& name) {
  for (auto& ps : s.problems)
    if (ps.problem->name() == problem)
      for (auto& ms : ps.methods)
        if (ms.info.name == name) return ms;
  throw std::runtime_error("no " + problem + "/" + name + " in the test study");
}

// Made-up timings on every row: median `ns`, spread +-`spread` relative, `reps` repetitions.
void set_timings(study& s, double ns, double spread, long reps) {
  s.timed = timing_settings{"full", 0.01, static_cast<int>(reps), 0.5, 2, 1000.0, 0, 1.0};
  for (auto& ps : s.problems)
    for (auto& ms : ps.methods)
      for (auto& r : ms.rows)
        if (!r.metrics.diverged && !r.metrics.failed) r.time = {ns, ns * (1 - spread), ns * (1 + spread), reps, false};
}

}  // namespace

// The fixture has external linkage: a TEST_F class (global) derives from it, and in the
// tests' unity unit this file is not the main file (-Wsubobject-linkage).
class compare_test : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("stepbench_compare_{}_{}", ::getpid(),
                                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const study& s, const std::string& name) const {
    write_study(s, path(name));
    return path(name);
  }
  // Writes both studies and compares the files as the command does.
  comparison compare(const study& base, const study& next, const compare_options& o = {}) const {
    return compare_studies(read_study(write(base, "base.h5")), read_study(write(next, "new.h5")), o);
  }

 private:
  fs::path dir_;
};

namespace {

// Rewrites one field of one row of /problems/<problem>/methods/<method>/runs in place,
// through a compound type holding only that field (HDF5 partial I/O).
void set_run_field(const std::string& file, const std::string& problem, const std::string& method_name,
                   const std::string& field, std::size_t row, double value) {
  H5::H5File f(file, H5F_ACC_RDWR);
  H5::DataSet ds = f.openDataSet("/problems/" + problem + "/methods/" + method_name + "/runs");
  H5::CompType one(sizeof(double));
  one.insertMember(field, 0, H5::PredType::NATIVE_DOUBLE);
  std::vector<double> v(static_cast<std::size_t>(ds.getSpace().getSimpleExtentNpoints()));
  ds.read(v.data(), one);
  v.at(row) = value;
  ds.write(v.data(), one);
}

void set_root_long(const std::string& file, const std::string& name, long value) {
  H5::H5File f(file, H5F_ACC_RDWR);
  f.removeAttr(name);
  H5::Attribute a = f.createAttribute(name, H5::PredType::NATIVE_LONG, H5::DataSpace());
  a.write(H5::PredType::NATIVE_LONG, &value);
}

std::vector<change> found(const comparison& c, change_kind k, const std::string& what) {
  std::vector<change> out;
  for (const auto& x : c.changes)
    if (x.kind == k && x.what == what) out.push_back(x);
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The decision functions.

TEST(compare_decisions, error_growth_beyond_the_factor_above_the_floor) {
  const double floor = 1e-12;
  EXPECT_EQ(judge_error(1e-6, 1e-4, floor, 2.0), change_kind::regression);
  EXPECT_EQ(judge_error(1e-6, 2.1e-6, floor, 2.0), change_kind::regression);
  EXPECT_EQ(judge_error(1e-6, 1.9e-6, floor, 2.0), std::nullopt);  // within the factor
  EXPECT_EQ(judge_error(1e-6, 1e-8, floor, 2.0), change_kind::improvement);
  EXPECT_EQ(judge_error(1e-6, 6e-7, floor, 2.0), std::nullopt);
  // Round-off: growth (or shrinkage) below the floor is neither.
  EXPECT_EQ(judge_error(1e-16, 9e-13, floor, 2.0), std::nullopt);
  EXPECT_EQ(judge_error(9e-13, 1e-16, floor, 2.0), std::nullopt);
  EXPECT_EQ(judge_error(0.0, 1e-13, floor, 2.0), std::nullopt);
  EXPECT_EQ(judge_error(0.0, 1e-11, floor, 2.0), change_kind::regression);  // from exact to above the floor
  // A non-finite error where there was a number.
  EXPECT_EQ(judge_error(1e-6, std::nan(""), floor, 2.0), change_kind::regression);
  EXPECT_EQ(judge_error(std::nan(""), std::nan(""), floor, 2.0), std::nullopt);
}

TEST(compare_decisions, order_and_agreement) {
  EXPECT_EQ(judge_order(4.0, 3.85, 0.1), change_kind::regression);
  EXPECT_EQ(judge_order(4.0, 3.95, 0.1), std::nullopt);
  EXPECT_EQ(judge_order(2.0, 2.2, 0.1), change_kind::improvement);
  EXPECT_EQ(judge_order(std::nan(""), 2.0, 0.1), std::nullopt);
  EXPECT_EQ(judge_agreement(1e-12, 1e-10, 2.0), change_kind::regression);
  EXPECT_EQ(judge_agreement(1e-15, 9e-14, 2.0), std::nullopt);         // below the 1e-13 floor
  EXPECT_EQ(judge_agreement(std::nan(""), 1e-10, 2.0), std::nullopt);  // not compared before
}

TEST(compare_decisions, timing_threshold_from_the_repetitions) {
  const timing tight{1000, 990, 1010, 5}, loose{1000, 900, 1100, 5}, single{1000, 1000, 1000, 1};
  EXPECT_DOUBLE_EQ(timing_threshold(tight, tight), 0.15);    // the floor (3 x 2 % is below it)
  EXPECT_DOUBLE_EQ(timing_threshold(tight, loose), 0.6);     // 3 x the larger spread, 20 %
  EXPECT_DOUBLE_EQ(timing_threshold(single, single), 0.25);  // no spread: the fallback
  EXPECT_DOUBLE_EQ(timing_threshold(single, loose), 0.6);    // the other side's spread still counts
  EXPECT_TRUE(std::isnan(spread(single)));
  EXPECT_DOUBLE_EQ(timing_threshold({1000, 900, 1080, 3}, tight), 0.54);  // spread 18 %
  EXPECT_EQ(judge_timing(2.0, 0.6), 1);
  EXPECT_EQ(judge_timing(1.5, 0.6), 0);
  EXPECT_EQ(judge_timing(0.5, 0.6), -1);
  EXPECT_EQ(judge_timing(0.7, 0.6), 0);
}

// ---------------------------------------------------------------------------------------
// Whole files.

TEST_F(compare_test, identical_files_compare_clean) {
  const study s = small_study({"damped_spring", "pendulum"});
  const std::string base = write(s, "base.h5"), again = write(s, "again.h5");
  for (const auto& next : {base, again}) {
    const comparison c = compare_studies(read_study(base), read_study(next));
    EXPECT_EQ(c.exit_status(), 0);
    EXPECT_TRUE(c.changes.empty()) << format_text(c);
    EXPECT_TRUE(c.added.empty());
    EXPECT_TRUE(c.removed.empty());
    EXPECT_TRUE(c.differences.empty()) << format_text(c);
    EXPECT_FALSE(c.timing_compared);
    EXPECT_EQ(c.timing_note, "neither file is timed");
  }
  // Two runs of the same sweep are the same numbers: accuracy is deterministic.
  const comparison c =
      compare_studies(read_study(base), read_study(write(small_study({"damped_spring", "pendulum"}), "rerun.h5")));
  EXPECT_EQ(c.exit_status(), 0) << format_text(c);
  EXPECT_TRUE(c.changes.empty()) << format_text(c);
}

TEST_F(compare_test, grown_error_in_one_row_is_a_regression_naming_the_row) {
  study s = small_study();
  const std::string base = write(s, "base.h5"), next = path("new.h5");
  fs::copy_file(base, next);
  const auto& rk4 = method(s, "damped_spring", "rk4");
  const std::size_t row = 2;
  set_run_field(next, "damped_spring", "rk4", "err_pos_max", row, 100 * rk4.rows[row].metrics.err_pos_max);
  const comparison c = compare_studies(read_study(base), read_study(next));
  EXPECT_EQ(c.exit_status(), 1);
  ASSERT_EQ(c.count(change_kind::regression), 1u) << format_text(c);
  const change& r = c.changes.front();
  EXPECT_EQ(r.problem, "damped_spring");
  EXPECT_EQ(r.method, "rk4");
  EXPECT_EQ(r.param_name, "dt");
  EXPECT_EQ(r.param, rk4.rows[row].param);
  EXPECT_EQ(r.what, "err_pos_max");
  EXPECT_NEAR(r.ratio, 100.0, 1e-9);
  // Every form names the row.
  const std::string dt = format_param(method_kind::fixed_step, rk4.rows[row].param);
  for (const auto& text : {format_text(c), format_markdown(c)}) {
    EXPECT_NE(text.find("REGRESSION"), std::string::npos);
    EXPECT_NE(text.find(dt), std::string::npos) << text;
    EXPECT_NE(text.find("err_pos_max"), std::string::npos);
  }
  // The reverse is an improvement, not a regression.
  const comparison back = compare_studies(read_study(next), read_study(base));
  EXPECT_EQ(back.exit_status(), 0);
  EXPECT_EQ(found(back, change_kind::improvement, "err_pos_max").size(), 1u);
  // A factor of 100 passes with --error-factor 1000.
  compare_options lax;
  lax.error_factor = 1000;
  EXPECT_EQ(compare_studies(read_study(base), read_study(next), lax).exit_status(), 0);
}

TEST_F(compare_test, newly_diverged_and_failed_rows) {
  study base = small_study(), next = small_study();
  auto& row = method(next, "damped_spring", "euler").rows.back();
  ASSERT_FALSE(method(base, "damped_spring", "euler").rows.back().metrics.diverged);
  row.metrics = run_metrics{};
  row.metrics.err_pos_max = row.metrics.err_pos_final = row.metrics.err_vel_final = row.metrics.err_pos_rms =
      std::nan("");
  row.metrics.diverged = true;
  row.metrics.note = "non-finite state at t = 3.2 s";
  method(next, "damped_spring", "velocity_verlet").rows[1].metrics.failed = true;
  const comparison c = compare(base, next);
  EXPECT_EQ(c.exit_status(), 1);
  const auto d = found(c, change_kind::regression, "diverged");
  ASSERT_EQ(d.size(), 1u) << format_text(c);
  EXPECT_EQ(d[0].method, "euler");
  EXPECT_EQ(d[0].param, row.param);
  EXPECT_EQ(d[0].note, "non-finite state at t = 3.2 s");
  EXPECT_TRUE(std::isnan(d[0].ratio));
  EXPECT_EQ(found(c, change_kind::regression, "failed").size(), 1u);
  // The errors of a row that diverged are not judged (they are NaN).
  EXPECT_TRUE(found(c, change_kind::regression, "err_pos_max").empty()) << format_text(c);
  // Back again: rows that no longer diverge or fail are improvements.
  const comparison back = compare(next, base);
  EXPECT_EQ(back.exit_status(), 0);
  EXPECT_EQ(found(back, change_kind::improvement, "diverged").size(), 1u);
  EXPECT_EQ(found(back, change_kind::improvement, "failed").size(), 1u);
}

// The reader fills the model the run fills: a study read back from its file holds the
// run's problem facts, truth outcome, fits and every row, field for field.
TEST_F(compare_test, a_study_read_back_is_the_study_written) {
  study s = small_study({"damped_spring", "bouncing_ball"}, {"rk4", "euler", "velocity_verlet", "gsl_rk4", "rk45"}, 5,
                        {"sweep", "stability"});
  set_timings(s, 250.0, 0.05, 3);
  const study r = read_study(write(s, "round.h5"));
  ASSERT_TRUE(r.record.has_value());
  EXPECT_EQ(r.record->format_version, study_format_version);
  EXPECT_TRUE(r.timed.has_value());
  EXPECT_FALSE(r.results.get<stability_data>().limits.empty());
  ASSERT_EQ(r.problems.size(), s.problems.size());
  const auto same = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
  for (const problem_study& w : s.problems) {  // the file's groups are in name order: found by name
    ASSERT_NE(r.find(w.name), nullptr) << w.name;
    const problem_study& q = *r.find(w.name);
    EXPECT_EQ(q.name, w.problem->name());
    EXPECT_EQ(q.unit, w.problem->position_unit());
    EXPECT_EQ(q.horizon, w.horizon);
    for (const auto& param : w.problem->params()) EXPECT_EQ(q.params.at(param.name), param.value) << param.name;
    EXPECT_EQ(q.truth.source, w.truth.source);
    EXPECT_EQ(q.truth.trusted, w.truth.trusted);
    EXPECT_EQ(q.truth.pos_scale, w.truth.pos_scale);
    EXPECT_EQ(q.truth.vel_scale, w.truth.vel_scale);
    ASSERT_EQ(q.truth.references.size(), w.truth.references.size());
    for (const reference_check& x : w.truth.references) {  // in name order in the file
      const auto found = std::find_if(q.truth.references.begin(), q.truth.references.end(),
                                      [&](const reference_check& r) { return r.source == x.source; });
      ASSERT_NE(found, q.truth.references.end()) << x.source;
      const reference_check& y = *found;
      EXPECT_EQ(y.status, x.status);
      EXPECT_EQ(y.compared_with, x.compared_with);
      if (!x.compared_with.empty()) {
        EXPECT_TRUE(same(y.vs.pos_rel, x.vs.pos_rel)) << x.source;
      }
    }
    ASSERT_EQ(q.methods.size(), w.methods.size());
    for (const method_study& a : w.methods) {
      ASSERT_NE(q.find(a.info.name), nullptr) << a.info.name;
      const method_study& b = *q.find(a.info.name);
      EXPECT_EQ(b.info.kind, a.info.kind);
      EXPECT_EQ(b.info.origin, a.info.origin);
      EXPECT_EQ(b.fit.state, a.fit.state) << a.info.name;
      EXPECT_TRUE(same(b.fit.order, a.fit.order)) << a.info.name;
      EXPECT_EQ(b.fit.levels, a.fit.levels) << a.info.name;
      ASSERT_EQ(b.rows.size(), a.rows.size());
      for (std::size_t k = 0; k < a.rows.size(); ++k) {
        const method_row &x = a.rows[k], &y = b.rows[k];
        EXPECT_EQ(y.param, x.param);
        EXPECT_EQ(y.steps, x.steps);
        EXPECT_EQ(y.work.force_evals, x.work.force_evals);
        EXPECT_TRUE(same(y.metrics.err_pos_max, x.metrics.err_pos_max)) << a.info.name << " " << k;
        EXPECT_TRUE(same(y.metrics.err_vel_final, x.metrics.err_vel_final));
        EXPECT_EQ(y.metrics.diverged, x.metrics.diverged);
        EXPECT_EQ(y.metrics.failed, x.metrics.failed);
        EXPECT_EQ(y.metrics.skipped, x.metrics.skipped);
        EXPECT_EQ(y.time.cut, x.time.cut);
        EXPECT_TRUE(same(y.time.time_ns_min, x.time.time_ns_min));
        EXPECT_TRUE(same(y.time.time_ns_max, x.time.time_ns_max));
        EXPECT_EQ(y.metrics.note, x.metrics.note);
        EXPECT_TRUE(same(y.time.time_ns, x.time.time_ns));
        EXPECT_EQ(y.time.repetitions, x.time.repetitions);
      }
    }
  }
}

// A stability limit that moves by more than stability_tolerance regresses; one that
// moves less is noise; a method that becomes unconditionally stable is a change of kind.
TEST_F(compare_test, a_moved_stability_limit_regresses) {
  const std::string file = write(small_study({"damped_spring"}, {"rk4"}, 5, {"sweep", "stability"}), "base.h5");
  const study a = read_study(file);
  study b = read_study(file);
  auto& limits = b.results.find<stability_data>()->limits;
  const auto finite = std::find_if(limits.begin(), limits.end(), [](const stability_limit& l) {
    return std::isfinite(l.theory) && l.integrator == "rk4" && l.test == stability_test::oscillator;
  });
  ASSERT_NE(finite, limits.end());
  EXPECT_NEAR(finite->theory, 2.0 * std::sqrt(2.0), 1e-6);  // RK4 on the oscillator: |y| < 2 sqrt 2
  finite->theory *= 1.0 + stability_tolerance / 2;
  EXPECT_EQ(compare_studies(a, b).count(change_kind::regression), 0u);
  finite->theory *= 1.0 + 2 * stability_tolerance;
  const comparison c = compare_studies(a, b);
  ASSERT_EQ(c.count(change_kind::regression), 1u) << format_text(c);
  EXPECT_EQ(c.changes[0].method, "rk4");
  EXPECT_EQ(c.changes[0].what, "oscillator stability limit (y = w dt or lambda dt)");
  finite->theory = std::nan("");
  finite->unconditionally_stable = true;
  const comparison kind = compare_studies(a, b);
  ASSERT_EQ(kind.count(change_kind::regression), 1u) << format_text(kind);
  EXPECT_EQ(kind.changes[0].what, "oscillator stability");
}

// A row skipped over the work budget has no result: newly skipped regresses, and its
// errors are not judged.
TEST_F(compare_test, newly_skipped_row) {
  const std::string file = write(small_study({"damped_spring"}, {"rk4"}), "base.h5");
  study a = read_study(file), b = read_study(file);
  const auto& ma = a.problems[0].methods[0];
  auto& last = b.problems[0].methods[0].rows.back().metrics;
  ASSERT_FALSE(ma.rows.back().metrics.skipped);
  last.skipped = true;
  last.err_pos_max = std::nan("");
  const comparison c = compare_studies(a, b);
  ASSERT_EQ(c.count(change_kind::regression), 1u) << format_text(c);
  EXPECT_EQ(c.changes[0].what, "skipped");
  EXPECT_EQ(c.changes[0].param, ma.rows.back().param);
  last.skipped = false;  // completed: its NaN error regresses
  const comparison completed = compare_studies(a, b);
  ASSERT_EQ(completed.count(change_kind::regression), 1u) << format_text(completed);
  EXPECT_EQ(completed.changes[0].what, "err_pos_max");
}

TEST_F(compare_test, order_drop_and_lost_fit) {
  study base = small_study(), next = small_study();
  ASSERT_EQ(method(base, "damped_spring", "rk4").fit.state, fit_result::status::fitted);
  method(next, "damped_spring", "rk4").fit.order -= 0.3;
  method(next, "damped_spring", "euler").fit.order += 0.05;  // within --order-drop
  auto& vv = method(next, "damped_spring", "velocity_verlet").fit;
  vv.state = fit_result::status::insufficient;
  vv.order = std::nan("");
  const comparison c = compare(base, next);
  EXPECT_EQ(c.exit_status(), 1);
  const auto o = found(c, change_kind::regression, "observed order");
  ASSERT_EQ(o.size(), 1u) << format_text(c);
  EXPECT_EQ(o[0].method, "rk4");
  EXPECT_TRUE(o[0].param_name.empty());
  const auto lost = found(c, change_kind::regression, "order fit");
  ASSERT_EQ(lost.size(), 1u);
  EXPECT_EQ(lost[0].method, "velocity_verlet");
  EXPECT_EQ(std::get<std::string>(lost[0].new_value), "insufficient");
  compare_options lax;
  lax.order_drop = 0.5;
  EXPECT_EQ(found(compare(base, next, lax), change_kind::regression, "observed order").size(), 0u);
}

TEST_F(compare_test, removed_method_is_listed_and_regresses_only_with_require_base) {
  const study base = small_study({"damped_spring"}, {"rk4", "euler", "gsl_rk4"});
  const study next = small_study({"damped_spring"}, {"rk4", "euler", "midpoint"});
  const comparison c = compare(base, next);
  ASSERT_EQ(c.removed.size(), 1u);
  EXPECT_EQ(c.removed[0].method, "gsl_rk4");
  EXPECT_EQ(c.removed[0].what, "method");
  ASSERT_EQ(c.added.size(), 1u);
  EXPECT_EQ(c.added[0].method, "midpoint");
  EXPECT_EQ(c.count(change_kind::regression), 0u);
  EXPECT_EQ(c.exit_status(), 0);  // only what both hold is compared
  compare_options require;
  require.require_base = true;
  EXPECT_EQ(compare(base, next, require).exit_status(), 1);  // the removal
  // Only added: never a regression.
  EXPECT_EQ(compare(small_study({"damped_spring"}, {"rk4"}), small_study({"damped_spring"}, {"rk4", "midpoint"}))
                .exit_status(),
            0);
  // A problem only in BASE is removed, only in NEW added.
  const comparison p =
      compare(small_study({"damped_spring", "pendulum"}, {"rk4"}), small_study({"damped_spring"}, {"rk4"}));
  ASSERT_EQ(p.removed.size(), 1u);
  EXPECT_EQ(p.removed[0].problem, "pendulum");
  EXPECT_EQ(p.removed[0].what, "problem");
}

TEST_F(compare_test, changed_ladder_is_reported_and_common_rows_compared) {
  const study five = small_study({"damped_spring"}, {"rk4"}, 5), six = small_study({"damped_spring"}, {"rk4"}, 6);
  const comparison finer = compare(five, six);
  ASSERT_EQ(finer.added.size(), 1u);
  EXPECT_EQ(finer.added[0].what, "ladder");
  EXPECT_NE(finer.added[0].detail.find("1 of 6 rows only in NEW"), std::string::npos) << finer.added[0].detail;
  EXPECT_NE(finer.added[0].detail.find("5 compared"), std::string::npos);
  EXPECT_EQ(finer.exit_status(), 0) << format_text(finer);
  EXPECT_FALSE(finer.differences.empty());  // levels 5 -> 6 is reported at the top
  const comparison coarser = compare(six, five);
  ASSERT_EQ(coarser.removed.size(), 1u);
  EXPECT_EQ(coarser.removed[0].what, "ladder");
  EXPECT_EQ(coarser.exit_status(), 0) << format_text(coarser);  // the rows both hold did not change
  compare_options require;
  require.require_base = true;
  EXPECT_EQ(compare(six, five, require).exit_status(), 1);
}

TEST_F(compare_test, references_and_truth) {
  study base = small_study({"damped_spring"}, {"rk4"}), next = small_study({"damped_spring"}, {"rk4"});
  auto& refs = next.problems[0].truth.references;
  ASSERT_GE(refs.size(), 2u);
  refs[0].status = "disagrees";
  refs[0].reason = "made up";
  refs[1].vs.pos_rel = std::max(refs[1].vs.pos_rel * 100, 1e-10);
  next.problems[0].truth.source = refs[1].source;
  const comparison c = compare(base, next);
  EXPECT_EQ(c.exit_status(), 1);
  const auto status = found(c, change_kind::regression, "reference " + refs[0].source + " status");
  ASSERT_EQ(status.size(), 1u) << format_text(c);
  EXPECT_EQ(std::get<std::string>(status[0].new_value), "disagrees");
  EXPECT_EQ(status[0].note, "made up");
  EXPECT_EQ(found(c, change_kind::regression, "reference " + refs[1].source + " err_pos_rel").size(), 1u);
  EXPECT_EQ(found(c, change_kind::regression, "truth_source").size(), 1u);
}

TEST_F(compare_test, timing_informs_and_gates_only_when_asked) {
  // 3 repetitions, +-2 % spread: threshold max(15 %, 3 x 4 %) = 15 %.
  study base = small_study({"damped_spring"}, {"rk4", "euler"}),
        next = small_study({"damped_spring"}, {"rk4", "euler"});
  set_timings(base, 1000, 0.02, 3);
  set_timings(next, 1000, 0.02, 3);
  for (auto& r : method(next, "damped_spring", "rk4").rows) r.time = {2000, 1960, 2040, 3, false};  // 2x slower
  method(next, "damped_spring", "euler").rows[0].time = {1120, 1098, 1142, 3, false};  // 12 %: within the noise
  const comparison c = compare(base, next);
  ASSERT_TRUE(c.timing_compared);
  EXPECT_EQ(c.slower(), method(next, "damped_spring", "rk4").rows.size()) << format_text(c);
  EXPECT_EQ(c.faster(), 0u);
  EXPECT_EQ(c.exit_status(), 0);  // timing informs
  for (const auto& t : c.timing) {
    EXPECT_NEAR(t.threshold, 0.15, 1e-12);
    EXPECT_EQ(t.flag, t.method == "rk4" ? 1 : 0) << t.method << " " << t.param;
  }
  const auto rk4 = std::find_if(c.timing_summaries.begin(), c.timing_summaries.end(),
                                [](const timing_summary& s) { return s.method == "rk4"; });
  ASSERT_NE(rk4, c.timing_summaries.end());
  EXPECT_NEAR(rk4->geomean, 2.0, 1e-9);
  compare_options gate;
  gate.gate_timing = true;
  EXPECT_EQ(compare(base, next, gate).exit_status(), 1);
  EXPECT_NE(format_text(c).find("slower"), std::string::npos);

  // The same 2x within a wide spread (+-40 % each side: threshold 240 %) is not flagged.
  set_timings(base, 1000, 0.4, 3);
  set_timings(next, 1000, 0.4, 3);
  for (auto& r : method(next, "damped_spring", "rk4").rows) r.time = {2000, 1200, 2800, 3, false};
  const comparison wide = compare(base, next, gate);
  EXPECT_EQ(wide.slower(), 0u);
  EXPECT_EQ(wide.exit_status(), 0);

  // A single repetition: no spread, the 25 % fallback, said in the output.
  set_timings(base, 1000, 0.0, 1);
  set_timings(next, 1200, 0.0, 1);
  const comparison single = compare(base, next);
  EXPECT_EQ(single.slower(), 0u);
  for (const auto& t : single.timing) EXPECT_DOUBLE_EQ(t.threshold, 0.25);
  EXPECT_NE(format_text(single).find("single repetition"), std::string::npos);

  // One side untimed: said, nothing compared.
  const comparison half = compare(base, small_study({"damped_spring"}, {"rk4", "euler"}));
  EXPECT_FALSE(half.timing_compared);
  EXPECT_EQ(half.timing_note, "NEW is not timed");
}

TEST_F(compare_test, files_that_cannot_be_compared) {
  const std::string base = write(small_study({"damped_spring"}, {"rk4"}), "base.h5");
  // Truncated: half the bytes.
  const std::string cut = path("cut.h5");
  {
    std::ifstream in(base, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  // A device that never ends, and a pipe that never does either, are refused unread.
  const std::string pipe = path("pipe.h5");
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  for (const auto& bad : {cut, path("missing.h5"), std::string("/dev/zero"), pipe}) {
    try {
      read_study(bad);
      ADD_FAILURE() << bad << " was read";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("'" + bad + "'"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  // A format this build does not read.
  const std::string v3 = path("v3.h5");
  fs::copy_file(base, v3);
  set_root_long(v3, "format_version", study_format_version + 1);
  EXPECT_THROW(read_study(v3), std::runtime_error);
  // Two files of different format versions (both readable by some build).
  study a = read_study(base), b = read_study(base);
  b.record->format_version = a.record->format_version + 1;
  try {
    compare_studies(a, b);
    ADD_FAILURE() << "different format versions compared";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("format_version"), std::string::npos) << e.what();
  }
  compare_options bad;
  bad.error_factor = 0.5;
  EXPECT_THROW(compare_studies(a, a, bad), std::invalid_argument);
}

TEST_F(compare_test, machine_and_build_differences_are_reported) {
  const std::string base = write(small_study({"damped_spring"}, {"rk4"}), "base.h5");
  study a = read_study(base), b = read_study(base);
  b.record->meta["cpu"] = "Another CPU";
  b.record->meta["git_commit"] = "0123456789ab";
  b.record->settings["cores"] = a.record->settings.at("cores") + 2;
  b.problems[0].params["k_s"] = 20;
  const comparison c = compare_studies(a, b);
  std::vector<std::string> what;
  for (const auto& d : c.differences) what.push_back(d.what);
  EXPECT_EQ(what, (std::vector<std::string>{"cpu", "cores", "git_commit", "damped_spring: k_s"}));
  EXPECT_EQ(c.exit_status(), 0);
  const std::string md = format_markdown(c);
  EXPECT_NE(md.find("| cpu |"), std::string::npos) << md;
  EXPECT_NE(md.find("Another CPU"), std::string::npos);
}

// The one table renderer every command prints with: aligned text and Markdown.
TEST(table_render, text_and_markdown) {
  table t{{{"method"}, right_column("time", "ns"), {"note"}}, {}};
  t.add({"rk4", "13.7", ""}).add({"velocity_verlet", "4.2", "a|b"});
  EXPECT_EQ(render_text(t),
            "  method           time [ns]  note\n"
            "  rk4                   13.7\n"
            "  velocity_verlet        4.2  a|b\n");
  EXPECT_EQ(render_markdown(t),
            "| method | time [ns] | note |\n"
            "|---|---:|---|\n"
            "| rk4 | 13.7 |   |\n"
            "| velocity_verlet | 4.2 | a\\|b |\n");
  EXPECT_THROW(t.add({"too", "few"}), std::logic_error);
  t.drop_column(2);
  EXPECT_EQ(render(t, table_format::text, ""),
            "method           time [ns]\nrk4                   13.7\nvelocity_verlet        4.2\n");
  EXPECT_EQ(wrap("one two three", "- ", "  ", 9), "- one two\n  three\n");
  EXPECT_EQ(plural(1, "row", "rows"), "1 row");
}

// `stepbench advise`: the decision on hand-made rows (every exclusion reason, the cost
// switch between time and force evaluations, the stability margin), and the reader on a
// real study file written by the sweep.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/advise.hpp"
#include "core/study_file.hpp"
#include "core/sweep.hpp"

using namespace stepbench;

namespace {

advise_row row(double dt, long evals, double err, double time_ns = NAN, bool cut = false, bool diverged = false) {
  advise_row r;
  r.param = dt;
  r.force_evals = evals;
  r.error = diverged ? NAN : err;
  r.time_ns = time_ns;
  r.cut = cut;
  r.diverged = diverged;
  return r;
}

advise_method method(std::string name, std::vector<advise_row> rows) {
  advise_method m;
  m.name = std::move(name);
  m.rows = std::move(rows);
  return m;
}

// A four-level ladder for three methods: a first-order one that never gets below 1e-3, a
// second-order one, and a fourth-order one that diverged at the coarsest dt.
advise_input untimed() {
  advise_input in;
  in.problem = "toy";
  in.methods.push_back(method("first", {row(0.4, 10, 0.4), row(0.2, 20, 0.2), row(0.1, 40, 0.1), row(0.05, 80, 0.05)}));
  in.methods.push_back(method("second", {row(0.4, 20, 1e-1), row(0.2, 40, 2.5e-2), row(0.1, 80, 6e-3), row(0.05, 160, 1.5e-3)}));
  in.methods.push_back(method("fourth", {row(0.4, 40, 0, NAN, false, true), row(0.2, 80, 1e-3), row(0.1, 160, 6e-5),
                                         row(0.05, 320, 4e-6)}));
  return in;
}

const advise_exclusion* excluded(const advise_result& r, std::string_view name) {
  for (const auto& e : r.excluded)
    if (e.method == name) return &e;
  return nullptr;
}

}  // namespace

TEST(advise, cheapest_qualifying_row_per_method_ranked_by_force_evals) {
  const auto r = advise(untimed(), 1e-2);
  EXPECT_EQ(r.cost, "force_evals");
  ASSERT_EQ(r.ranked.size(), 2u);
  // fourth reaches 1e-3 at dt 0.2 with 80 evals; second reaches 6e-3 at dt 0.1, also 80
  // evals: the tie goes to the lower error.
  EXPECT_EQ(r.ranked[0].method, "fourth");
  EXPECT_DOUBLE_EQ(r.ranked[0].row.param, 0.2);
  EXPECT_EQ(r.ranked[1].method, "second");
  EXPECT_DOUBLE_EQ(r.ranked[1].row.param, 0.1);
  // Stable at the chosen dt even though it diverged at a coarser one; the margin is shown.
  ASSERT_TRUE(r.ranked[0].largest_diverged.has_value());
  EXPECT_DOUBLE_EQ(*r.ranked[0].largest_diverged, 0.4);
  EXPECT_DOUBLE_EQ(*r.ranked[0].smallest_diverged, 0.4);
  EXPECT_EQ(r.ranked[0].diverged_rows, 1);
  EXPECT_NE(format_advice(r).find("use fourth at dt 0.2 s: 80 force evals, err_pos_max 0.001 m; diverged at dt 0.4 s"),
            std::string::npos)
      << format_advice(r);
  EXPECT_FALSE(r.ranked[1].largest_diverged.has_value());
  const auto* e = excluded(r, "first");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->reason, "too inaccurate: best err_pos_max 0.05 m at dt 0.05 s");
  EXPECT_FALSE(r.best_achieved.has_value());
}

TEST(advise, diverged_everywhere_and_missing_metric_are_reasons) {
  auto in = untimed();
  in.methods.push_back(method("blowup", {row(0.4, 10, 0, NAN, false, true), row(0.2, 20, 0, NAN, false, true)}));
  auto peer = method("peer_rk", {row(0.1, 40, NAN)});
  peer.peer = true;
  peer.has_metric = false;
  in.methods.push_back(peer);
  const auto r = advise(in, 1e-2);
  ASSERT_NE(excluded(r, "blowup"), nullptr);
  EXPECT_EQ(excluded(r, "blowup")->reason, "diverged at every dt");
  ASSERT_NE(excluded(r, "peer_rk"), nullptr);
  EXPECT_EQ(excluded(r, "peer_rk")->reason, "no err_pos_max recorded for this peer");
}

TEST(advise, time_is_the_cost_when_every_qualifying_row_is_timed) {
  auto in = untimed();
  in.timings = true;
  // second is cheaper per evaluation in time than fourth: 80 evals in 500 ns vs 80 in 900 ns.
  for (auto& m : in.methods)
    for (auto& r : m.rows) r.time_ns = r.force_evals * (m.name == "second" ? 6.25 : 11.25);
  const auto r = advise(in, 1e-2);
  EXPECT_EQ(r.cost, "time_ns");
  ASSERT_EQ(r.ranked.size(), 2u);
  EXPECT_EQ(r.ranked[0].method, "second");
  EXPECT_DOUBLE_EQ(r.ranked[0].cost, 500.0);
  // One qualifying row without a time: the ranking falls back to force evaluations.
  in.methods[2].rows[2].time_ns = NAN;
  EXPECT_EQ(advise(in, 1e-2).cost, "force_evals");
}

TEST(advise, cut_rows_are_too_slow) {
  auto in = untimed();
  in.timings = true;
  for (auto& m : in.methods)
    for (auto& r : m.rows) r.time_ns = 10.0 * r.force_evals;
  // Only the two finest rows of fourth reach 1e-4, and both were cut by the budget.
  in.methods[2].rows[2].cut = in.methods[2].rows[3].cut = true;
  in.methods[2].rows[2].time_ns = in.methods[2].rows[3].time_ns = NAN;
  const auto r = advise(in, 1e-4);
  EXPECT_TRUE(r.ranked.empty());
  ASSERT_NE(excluded(r, "fourth"), nullptr);
  EXPECT_EQ(excluded(r, "fourth")->reason,
            "too slow: cut by the time budget (would reach err_pos_max 4e-06 m at dt 0.05 s)");
}

TEST(advise, no_method_meets_the_tolerance_names_the_best) {
  const auto r = advise(untimed(), 1e-9);
  EXPECT_TRUE(r.ranked.empty());
  ASSERT_TRUE(r.best_achieved.has_value());
  EXPECT_EQ(r.best_achieved->method, "fourth");
  EXPECT_DOUBLE_EQ(r.best_achieved->row.error, 4e-6);
  const std::string text = format_advice(r);
  EXPECT_NE(text.find("no method in the study meets err_pos_max <= 1e-09 m on toy; the best achieved is err_pos_max "
                      "4e-06 m by fourth at dt 0.05 s"),
            std::string::npos)
      << text;
  EXPECT_EQ(r.excluded.size(), 3u);
}

TEST(advise, adaptive_peers_report_a_tolerance) {
  advise_input in;
  in.problem = "toy";
  auto cv = method("cvode_bdf", {row(1e-4, 300, 2e-3), row(1e-6, 900, 3e-5), row(1e-8, 2000, 4e-7)});
  cv.peer = cv.adaptive = true;
  in.methods.push_back(cv);
  const auto r = advise(in, 1e-4);
  ASSERT_EQ(r.ranked.size(), 1u);
  EXPECT_EQ(format_param(r.ranked[0]), "rtol 1e-06");
  EXPECT_THROW(advise(in, 0.0), std::invalid_argument);
  EXPECT_THROW(advise(in, NAN), std::invalid_argument);
}

// The reader on a file the sweep wrote: every integrator is a candidate with its rows as
// the sweep computed them, and the answer is the cheapest row meeting the tolerance.
TEST(advise, reads_a_study_file) {
  sweep_options opts;
  opts.problems = {"damped_spring"};
  opts.levels = 6;
  const study s = run_sweep(opts);
  const auto path = (std::filesystem::temp_directory_path() / fmt::format("test_advise_{}.h5", ::getpid())).string();
  write_study(s, path);
  const auto in = read_advise_input(path, "damped_spring", "err_pos_final");
  EXPECT_FALSE(in.timings);
  EXPECT_EQ(in.unit, "m");
  ASSERT_EQ(in.methods.size(), s.problems.front().integrators.size());
  double best_evals = INFINITY;
  std::string best_name;
  for (const auto& is : s.problems.front().integrators) {
    const auto it = std::find_if(in.methods.begin(), in.methods.end(), [&](const auto& m) { return m.name == is.info.name; });
    ASSERT_NE(it, in.methods.end()) << is.info.name;
    ASSERT_EQ(it->rows.size(), is.rows.size());
    for (std::size_t k = 0; k < is.rows.size(); ++k) {
      EXPECT_DOUBLE_EQ(it->rows[k].param, is.rows[k].dt);
      EXPECT_EQ(it->rows[k].force_evals, is.rows[k].force_evals);
      EXPECT_DOUBLE_EQ(it->rows[k].error, is.rows[k].metrics.err_pos_final);
      if (is.rows[k].metrics.err_pos_final <= 1e-4 && is.rows[k].force_evals < best_evals) {
        best_evals = static_cast<double>(is.rows[k].force_evals);
        best_name = is.info.name;
      }
    }
  }
  const auto r = advise(in, 1e-4);
  ASSERT_FALSE(r.ranked.empty());
  EXPECT_EQ(r.ranked.front().method, best_name);
  EXPECT_DOUBLE_EQ(r.ranked.front().cost, best_evals);

  try {
    read_advise_input(path, "nope");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("problem 'nope' is not in the study file"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(it has: damped_spring)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_advise_input(path, "damped_spring", "err_bogus"), std::invalid_argument);
  std::filesystem::remove(path);
  EXPECT_THROW(read_advise_input(path, "damped_spring"), std::runtime_error);
  // Not an HDF5 file at all.
  std::ofstream(path) << "not hdf5\n";
  EXPECT_THROW(read_advise_input(path, "damped_spring"), std::runtime_error);
  std::filesystem::remove(path);
}

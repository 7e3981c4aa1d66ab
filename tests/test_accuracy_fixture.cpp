// The accuracy tables of the default study against values produced by the code before
// the one-study refactor (issue 7), stored in tests/data/accuracy_before_issue7.json:
// our methods' rows must be bit-identical (the refactor moved code, it must not move a
// single rounding), and the peers' errors must agree with the old benchmark's to
// round-off. Any later change to a step that alters these numbers fails here and must
// say why.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "default_study.hpp"
#include "judge/verdict.hpp"
#include "run/sweep.hpp"

using namespace stepbench;
using stepbench::test_support::default_study;

namespace {

nlohmann::json fixture() {
  std::ifstream in(STEPBENCH_TEST_DATA "/accuracy_before_issue7.json");
  EXPECT_TRUE(in.good()) << "cannot open the fixture";
  return nlohmann::json::parse(in, nullptr, true, /*ignore_comments=*/false);
}

const problem_study* find_problem(const std::string& key) {
  for (const auto& ps : default_study().problems)
    if (ps.problem->name() == key.substr(0, key.find('/'))) return &ps;
  return nullptr;
}

const method_study* find(const std::string& key) {
  if (const auto* ps = find_problem(key))
    for (const auto& ms : ps->methods)
      if (ms.info.name == key.substr(key.find('/') + 1)) return &ms;
  return nullptr;
}

// The order fitted on the fixture's rows only: the study's ladder runs on beyond them,
// and the fit over the longer ladder may choose other levels.
double order_on_first_rows(const std::string& key, std::size_t rows) {
  method_study prefix = *find(key);
  prefix.rows.resize(rows);
  fit_rows(prefix, find_problem(key)->truth.pos_scale);
  return prefix.fit.order;
}

// JSON has no NaN: the fixture writes it as null (nlohmann) or NaN (Python); both read as NaN here.
double number(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : std::nan(""); }

bool same_bits(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

}  // namespace

TEST(accuracy_fixture, our_rows_are_bit_identical) {
  const auto fx = fixture();
  std::size_t compared = 0;
  for (const auto& [key, expected] : fx["ours"].items()) {
    const method_study* ms = find(key);
    ASSERT_NE(ms, nullptr) << key;
    const auto& rows = expected["rows"];
    // The fixture's ladders end at tol 1e-12 and at 12 levels; the study's run on to 1e-14
    // and, for fixed steps, on to round-off or the work budget (issue 18): its first rows
    // are the fixture's, in the same order.
    if (ms->info.kind == method_kind::adaptive)
      ASSERT_EQ(ms->rows.size(), rows.size() + 2) << key;
    else
      ASSERT_GE(ms->rows.size(), rows.size()) << key;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto& r = rows[i];
      const auto& got = ms->rows[i];
      const auto& m = got.metrics;
      EXPECT_TRUE(same_bits(got.param, number(r["dt"]))) << key << " row " << i;
      EXPECT_EQ(got.steps, r["steps"].get<long>()) << key << " row " << i;
      EXPECT_EQ(got.work.force_evals, r["force_evals"].get<long>()) << key << " row " << i;
      for (const auto& [field, value] : {std::pair{"err_pos_final", m.err_pos_final},
                                         {"err_vel_final", m.err_vel_final},
                                         {"err_pos_max", m.err_pos_max},
                                         {"err_pos_rms", m.err_pos_rms},
                                         {"energy_drift", m.energy_drift},
                                         {"energy_err_max", m.energy_err_max}}) {
        EXPECT_TRUE(same_bits(value, number(r[field])))
            << key << " row " << i << " " << field << ": " << value << " != " << number(r[field]);
        ++compared;
      }
      EXPECT_EQ(m.diverged, r["diverged"].get<int>() != 0) << key << " row " << i;
    }
    EXPECT_TRUE(same_bits(order_on_first_rows(key, rows.size()), number(expected["observed_order"]))) << key;
  }
  EXPECT_EQ(compared, 24u * 12u * 6u);
}

TEST(accuracy_fixture, peer_errors_agree_with_the_old_benchmark) {
  const auto fx = fixture();
  for (const auto& [key, expected] : fx["peers"].items()) {
    const method_study* ms = find(key);
    ASSERT_NE(ms, nullptr) << key;
    const auto& rows = expected["rows"];
    // The fixture's ladders end at tol 1e-12 and at 12 levels; the study's run on to 1e-14
    // and, for fixed steps, on to round-off or the work budget (issue 18): its first rows
    // are the fixture's, in the same order.
    if (ms->info.kind == method_kind::adaptive)
      ASSERT_EQ(ms->rows.size(), rows.size() + 2) << key;
    else
      ASSERT_GE(ms->rows.size(), rows.size()) << key;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto& r = rows[i];
      const auto& got = ms->rows[i];
      EXPECT_EQ(got.param, number(r["param"])) << key;
      EXPECT_EQ(got.steps, r["steps"].get<long>()) << key << " row " << i;
      EXPECT_EQ(got.work.force_evals, r["force_evals"].get<long>()) << key << " row " << i;
      for (const auto& [field, value] :
           {std::pair{"err_pos_final", got.metrics.err_pos_final}, {"err_pos_max", got.metrics.err_pos_max}}) {
        const double old = number(r[field]);
        if (std::isnan(old)) {
          EXPECT_TRUE(std::isnan(value)) << key << " row " << i << " " << field;
        } else {
          EXPECT_NEAR(value, old, 1e-12 * std::abs(old)) << key << " row " << i << " " << field;
        }
      }
    }
  }
}

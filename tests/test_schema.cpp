// The study file's schema (store/schema.hpp) is what the writer checks each table
// against: a table whose columns differ from the declaration in name, order or type is
// refused before anything is written, and the timing group comes whole or not at all.
#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "store/h5.hpp"
#include "store/schema.hpp"
#include "store/study_file.hpp"

namespace stepbench {
namespace {

H5::H5File in_memory_file() {
  H5::FileAccPropList in_memory;
  in_memory.setCore(1 << 16, false);
  return H5::H5File("schema_test.h5", H5F_ACC_TRUNC, H5::FileCreatPropList::DEFAULT, in_memory);
}

// The schema's table `name`.
const schema::table& schema_table(std::string_view name) {
  for (const auto& t : schema::tables())
    if (t.name == name) return t;
  throw std::logic_error("the study schema has no table named " + std::string(name));
}

h5::table front(bool with_error_column = true) {
  h5::table t;
  t.add("method", std::vector<std::string>{"rk4"});
  t.add("param", std::vector<double>{0.1});
  t.add("cost", std::vector<double>{40.0});
  if (with_error_column) t.add("err_pos_max", std::vector<double>{1e-6});
  return t;
}

TEST(schema, a_table_as_declared_is_written) {
  H5::H5File f = in_memory_file();
  EXPECT_NO_THROW(front().write(f, "front_force_evals", schema_table("front")));
  EXPECT_TRUE(h5::is_dataset(f, "front_force_evals"));
}

TEST(schema, a_missing_renamed_or_retyped_column_is_refused) {
  H5::H5File f = in_memory_file();
  EXPECT_THROW(front(false).write(f, "a", schema_table("front")), std::logic_error);
  h5::table extra = front();
  extra.add("surprise", std::vector<double>{1.0});
  EXPECT_THROW(extra.write(f, "b", schema_table("front")), std::logic_error);
  h5::table retyped;
  retyped.add("method", std::vector<std::string>{"rk4"});
  retyped.add("param", std::vector<std::int64_t>{1});  // declared f64
  retyped.add("cost", std::vector<double>{40.0});
  retyped.add("err_pos_max", std::vector<double>{1e-6});
  EXPECT_THROW(retyped.write(f, "c", schema_table("front")), std::logic_error);
  EXPECT_FALSE(h5::has_link(f, "a") || h5::has_link(f, "b") || h5::has_link(f, "c"));
}

TEST(schema, the_timing_group_is_whole_or_absent) {
  H5::H5File f = in_memory_file();
  const std::vector<method_row> rows(2);
  EXPECT_NO_THROW(runs_columns().table(rows, false).write(f, "untimed", schema_table("runs")));
  EXPECT_NO_THROW(runs_columns().table(rows, true).write(f, "timed", schema_table("runs")));
  h5::table partial = runs_columns().table(rows, false);
  partial.add("time_ns", std::vector<double>{1.0, 2.0});  // the rest of the timing group missing
  EXPECT_THROW(partial.write(f, "partial", schema_table("runs")), std::logic_error);
}

TEST(schema, the_json_is_the_declaration) {
  const auto j = nlohmann::json::parse(schema::to_json());
  EXPECT_EQ(j["format_version"].get<int>(), study_format_version);
  EXPECT_EQ(j["param_kind"]["fixed_step"], "dt");
  EXPECT_EQ(j["param_kind"]["adaptive"], "tolerance");
  EXPECT_EQ(j["row_incomplete_flags"].size(), 3u);
  EXPECT_EQ(j["tables"].size(), schema::tables().size());  // the parts' own tables: `stepbench schema`
  const auto& runs = j["tables"]["runs"]["groups"];
  EXPECT_EQ(runs[0]["fields"][0][0], "param");
  EXPECT_TRUE(runs[1]["timed_only"].get<bool>());
}

}  // namespace
}  // namespace stepbench

#pragma once
// The study file's schema: its format version, every table's fields with their types (the
// tables of the column maps that write and read them, store/columns.hpp), the "row
// completed" rule and what a method's `param` is (core/method.hpp). The C++ writer checks
// each table it writes against it (h5::table::write), and the Python report reads it from
// scripts/stepbench_report/schema.json, which `stepbench schema` prints and a test
// compares with this file's (docs/study-format.md says what each field means).
#include <array>
#include <span>
#include <string>
#include <string_view>

namespace stepbench::schema {

// Bump when the layout changes incompatibly; readers refuse other versions.
inline constexpr int format_version = 4;

enum class field_type { f64, i64, i8, str };
std::string_view to_string(field_type t);

struct field {
  std::string_view name;
  field_type type;
};

// Consecutive fields of a table; a timed-only group is present exactly when the study
// was timed (stepbench_bench --study_out), as a whole.
struct field_group {
  std::span<const field> fields;
  bool timed_only = false;
};

struct table {
  std::string_view name;   // the schema's name for it ("runs", "front")
  std::string_view where;  // where it lives in the file, for the reader and the docs
  std::span<const field_group> groups;
  // Written only when the study has rows for it (/verdict/plugin_equal_error: only a study
  // that swept a plugin's method): a reader or a merge takes its absence as no rows.
  bool optional = false;
};

// Every table of the study file, the loop, energy and substeps studies included.
std::span<const table> tables();

// The "row completed" rule as data: a row completed when every one of these flags is 0
// (core/measure.hpp's row_completed is the same rule in C++).
inline constexpr std::array<std::string_view, 3> row_incomplete_flags{"diverged", "failed", "skipped"};

// The whole schema as JSON text (`stepbench schema`; scripts/stepbench_report/schema.json):
// these tables, then `own`, those a study part declares in its own file (parts/part.hpp).
std::string to_json(std::span<const table* const> own = {});

}  // namespace stepbench::schema

// `stepbench schema`: the study file's schema (store/schema.hpp) as JSON, the text the
// Python report reads as scripts/stepbench_report/schema.json (a test compares the two).
#include "store/schema.hpp"

#include <cstdio>

#include "cli/commands.hpp"
#include "parts/part.hpp"

namespace stepbench::cli {

command add_schema(CLI::App& app) {
  auto* sub = app.add_subcommand("schema", "print the study file's schema (format version, tables, fields) as JSON");
  return {sub, [] {
            std::fputs(schema::to_json(parts_tables()).c_str(), stdout);
            return 0;
          }};
}

}  // namespace stepbench::cli

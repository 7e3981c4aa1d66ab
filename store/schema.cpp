#include "store/schema.hpp"

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/method.hpp"
#include "store/challenge.hpp"
#include "store/energy.hpp"
#include "store/loop.hpp"
#include "store/scan.hpp"
#include "store/stability.hpp"
#include "store/study_file.hpp"
#include "store/substeps.hpp"
#include "store/verdict.hpp"

namespace stepbench::schema {

std::string_view to_string(field_type t) {
  constexpr std::string_view names[] = {"f64", "i64", "i8", "str"};
  return names[static_cast<int>(t)];
}

// Each file's column maps' tables (store/columns.hpp), in the study file's order.
std::span<const table> tables() {
  static const std::vector<table> all = [] {
    std::vector<table> out;
    for (const auto& file : {problems_tables(), stability_tables(), energy_tables(), loop_tables(), substeps_tables(),
                             verdict_file_tables(), scan_tables(), challenge_tables()})
      out.insert(out.end(), file.begin(), file.end());
    return out;
  }();
  return all;
}

std::string to_json(std::span<const table* const> own) {
  nlohmann::ordered_json out;
  out["format_version"] = format_version;
  out["row_incomplete_flags"] = row_incomplete_flags;
  for (const auto k : {method_kind::fixed_step, method_kind::adaptive})
    out["param_kind"][std::string(to_string(k))] = param_name(k);
  out["parameter_kinds"] = {"real", "whole", "named"};
  std::vector<const table*> every;
  for (const auto& t : tables()) every.push_back(&t);
  every.insert(every.end(), own.begin(), own.end());
  for (const table* tp : every) {
    const table& t = *tp;
    nlohmann::ordered_json groups = nlohmann::ordered_json::array();
    for (const auto& g : t.groups) {
      nlohmann::ordered_json fields = nlohmann::ordered_json::array();
      for (const auto& f : g.fields) fields.push_back({f.name, to_string(f.type)});
      groups.push_back({{"timed_only", g.timed_only}, {"fields", fields}});
    }
    out["tables"][std::string(t.name)] = {{"where", t.where}, {"groups", groups}};
  }
  return out.dump(1) + "\n";
}

}  // namespace stepbench::schema

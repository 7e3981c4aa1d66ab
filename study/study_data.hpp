#pragma once
// A study file as the commands that answer from it read it (advise, compare, ratios):
// every method's `runs` table as columns by field name (store/study_reader.hpp reads it).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/method.hpp"

namespace stepbench {

struct study_method {
  std::string name;
  method_origin origin = method_origin::ours;
  method_kind kind = method_kind::fixed_step;
  std::string description, library;
  double declared_order = 0.0;  // NaN when none
  std::string fit_status;       // "fitted", "exact", "insufficient"
  double fit_slope = 0.0;       // observed order (fixed-step) or error-per-tolerance slope (adaptive)
  int declared_order_holds = -1;
  std::vector<long> fit_levels;
  // The `runs` table: every numeric field as doubles (integers converted), by name.
  std::map<std::string, std::vector<double>> columns;
  std::vector<std::string> notes;
  std::size_t rows() const { return columns.at("param").size(); }
  const std::vector<double>& col(const std::string& field) const;  // throws naming a missing field
};

struct study_reference {
  std::string source, status, reason, compared_with;
  double err_pos_rel = 0.0, err_vel_rel = 0.0;
  bool is_truth = false;
};

struct study_problem {
  std::string name, unit, truth_source;
  bool truth_trusted = true;
  double horizon = 0.0, pos_scale = 1.0, vel_scale = 1.0;
  std::map<std::string, double> params;  // every numeric attribute of the problem group
  std::vector<study_reference> references;
  std::vector<study_method> methods;
  const study_method* find(const std::string& method) const;
};

// One row of /stability/limits.
struct study_stability_limit {
  std::string integrator, test;
  double theory = 0.0, measured = 0.0;  // NaN where they do not apply
  bool unstable_for_all_dt = false, unconditionally_stable = false;
};

struct study_data {
  std::string path;
  long format_version = 0;
  std::map<std::string, std::string> meta;  // string root attributes (version, compiler, cpu, ...)
  std::map<std::string, double> settings;   // numeric scalar root attributes (cores, levels, base_steps, ...)
  bool timed = false;
  std::vector<study_problem> problems;
  std::vector<study_stability_limit> stability;  // empty when the file has no /stability
  const study_problem* find(const std::string& problem) const;
};

}  // namespace stepbench

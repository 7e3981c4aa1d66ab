#include "store/schema.hpp"

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/method.hpp"

namespace stepbench::schema {
namespace {

using enum field_type;

// /problems/<p>/methods/<m>/runs (and the substeps study's runs): one row per ladder entry.
constexpr field run_fields[] = {{"param", f64},
                                {"steps", i64},
                                {"rejected_steps", i64},
                                {"force_evals", i64},
                                {"jacobian_evals", i64},
                                {"newton_iterations", i64},
                                {"linear_solves", i64},
                                {"err_pos_final", f64},
                                {"err_vel_final", f64},
                                {"err_pos_max", f64},
                                {"err_pos_rms", f64},
                                {"energy_drift", f64},
                                {"energy_err_max", f64},
                                {"angmom_drift", f64},
                                {"angmom_err_max", f64},
                                {"constraint_violation_max", f64},
                                {"contacts", i64},
                                {"contact_count_err", f64},
                                {"contact_time_err", f64},
                                {"contact_pos_err", f64},
                                {"tunnelled", i64},
                                {"max_penetration", f64},
                                {"diverged", i8},
                                {"failed", i8},
                                {"skipped", i8},
                                {"note", str}};
constexpr field run_timing_fields[] = {
    {"time_ns", f64}, {"time_ns_min", f64}, {"time_ns_max", f64}, {"repetitions", i64}, {"cut", i8}};
constexpr field substep_fields[] = {{"substeps", i64}, {"extra_damping", f64}};
constexpr field parameter_fields[] = {{"name", str},       {"value", f64},   {"unit", str},    {"kind", str},
                                      {"value_name", str}, {"default", f64}, {"allowed", str}, {"description", str}};
constexpr field equal_error_fields[] = {
    {"metric", str},  {"target", f64},      {"rank", i64},        {"method", str},  {"origin", str},  {"kind", str},
    {"param", f64},   {"error", f64},       {"cost_kind", str},   {"cost", f64},    {"cost_lo", f64}, {"cost_hi", f64},
    {"time_ns", f64}, {"force_evals", f64}, {"interpolated", i8}, {"is_answer", i8}};
constexpr field front_fields[] = {{"method", str}, {"param", f64}, {"cost", f64}, {"err_pos_max", f64}};
constexpr field limit_fields[] = {{"integrator", str},
                                  {"test", str},
                                  {"measured", f64},
                                  {"theory", f64},
                                  {"rel_difference", f64},
                                  {"unstable_for_all_dt", i8},
                                  {"unconditionally_stable", i8},
                                  {"run_confirms", i8},
                                  {"step_failed_at", f64},
                                  {"note", str}};
constexpr field energy_fields[] = {{"method", str},
                                   {"symplectic", i8},
                                   {"dt", f64},
                                   {"steps", i64},
                                   {"force_evals", i64},
                                   {"completed", i8},
                                   {"max_rel_err", f64},
                                   {"final_rel_err", f64},
                                   {"drift_per_period", f64},
                                   {"first_tenth_max", f64},
                                   {"last_tenth_max", f64},
                                   {"last_tenth_mean", f64},
                                   {"verdict", str},
                                   {"drift_sign", i64},
                                   {"angmom_max_rel_err", f64},
                                   {"angmom_drift_per_period", f64},
                                   {"seconds", f64},
                                   {"note", str}};
constexpr field loop_fields[] = {{"design", str},
                                 {"clock", str},
                                 {"display_hz", f64},
                                 {"physics_hz", f64},
                                 {"dt", f64},
                                 {"substeps", i64},
                                 {"clamp_s", f64},
                                 {"jitter_seed", i64},
                                 {"stall_at_s", f64},
                                 {"frames", i64},
                                 {"physics_steps", i64},
                                 {"force_evals", i64},
                                 {"shown_err_max", f64},
                                 {"shown_err_rms", f64},
                                 {"final_shown_err", f64},
                                 {"clock_dependence", f64},
                                 {"physics_clock_dependence", f64},
                                 {"judder", f64},
                                 {"lag_s", f64},
                                 {"lag_clock_s", f64},
                                 {"steps_per_frame_mean", f64},
                                 {"steps_per_frame_max", i64},
                                 {"stall_burst_steps", i64},
                                 {"clamp_hits", i64},
                                 {"alpha_min", f64},
                                 {"alpha_max", f64},
                                 {"physics_t", f64},
                                 {"diverged", i8},
                                 {"note", str},
                                 {"step_cost_ns", f64},
                                 {"frame_budget_ns", f64},
                                 {"worst_frame_work_ns", f64},
                                 {"late_frames", i64},
                                 {"physics_load", f64},
                                 {"outcome", str},
                                 {"outcome_without_clamp", str},
                                 {"clamp_prevented_spiral", i8}};
constexpr field loop_cheapest_fields[] = {{"display_hz", f64},   {"target", f64},     {"found", i8},
                                          {"design", str},       {"physics_hz", f64}, {"steps_per_frame_mean", f64},
                                          {"shown_err_max", f64}};
constexpr field substeps_verdict_fields[] = {{"implicit_method", str},
                                             {"explicit_method", str},
                                             {"cost_kind", str},
                                             {"implicit_cost", f64},
                                             {"implicit_error", f64},
                                             {"implicit_damping", f64},
                                             {"substeps_at_equal_cost", i64},
                                             {"explicit_cost", f64},
                                             {"explicit_error", f64},
                                             {"explicit_damping", f64},
                                             {"substeps_to_match", i64},
                                             {"cost_to_match", f64},
                                             {"summary", str}};

constexpr field verdict_equal_error_fields[] = {{"problem", str},          {"unit", str},
                                                {"target", f64},           {"ours_method", str},
                                                {"ours_kind", str},        {"ours_param", f64},
                                                {"ours_cost", f64},        {"ours_cost_lo", f64},
                                                {"ours_cost_hi", f64},     {"ours_interpolated", i8},
                                                {"peer_method", str},      {"peer_kind", str},
                                                {"peer_param", f64},       {"peer_cost", f64},
                                                {"peer_cost_lo", f64},     {"peer_cost_hi", f64},
                                                {"peer_interpolated", i8}, {"ratio", f64},
                                                {"cost_kind", str},        {"verdict", str},
                                                {"best_error", f64}};
constexpr field frame_rate_fields[] = {{"problem", str}, {"unit", str},        {"hz", f64},  {"method", str},
                                       {"stable", i8},   {"err_pos_max", f64}, {"note", str}};
constexpr field frame_answer_fields[] = {{"problem", str},     {"unit", str},           {"hz", f64},
                                         {"target", f64},      {"method", str},         {"substeps", i64},
                                         {"err_pos_max", f64}, {"cost_per_frame", f64}, {"frame_share", f64}};
constexpr field frame_rate_run_fields[] = {
    {"hz", f64},          {"method", str},         {"substeps", i64},    {"dt", f64},
    {"completed", i8},    {"diverged", i8},        {"err_pos_max", f64}, {"steps", i64},
    {"force_evals", f64}, {"cost_per_frame", f64}, {"note", str}};
// A scan (study/scan.hpp): its grid points, every run, and the cheapest run at each
// point and rate; the axis values are the 2-D dataset /scan/<name>/values beside them.
constexpr field scan_point_fields[] = {{"point", i64},   {"trusted", i8},    {"truth_source", str},
                                       {"horizon", f64}, {"pos_scale", f64}, {"note", str}};
constexpr field scan_run_fields[] = {{"point", i64},
                                     {"hz", f64},
                                     {"method", str},
                                     {"substeps", i64},
                                     {"dt", f64},
                                     {"completed", i8},
                                     {"diverged", i8},
                                     {"failed", i8},
                                     {"skipped", i8},
                                     {"err_pos_max", f64},
                                     {"steps", i64},
                                     {"force_evals", f64},
                                     {"newton_iterations", f64},
                                     {"note", str}};
constexpr field scan_best_fields[] = {{"point", i64},    {"hz", f64},          {"method", str},
                                      {"substeps", i64}, {"err_pos_max", f64}, {"force_evals_per_frame", f64}};

// The pendulum challenge and the Small Steps experiment (study/challenge.hpp).
constexpr field challenge_entry_fields[] = {{"method", str},
                                            {"steps_per_frame", i64},
                                            {"tolerance", f64},
                                            {"ns_per_frame", f64},
                                            {"err_pos_max", f64},
                                            {"energy_drift", f64},
                                            {"energy_err_max", f64},
                                            {"link_err_max", f64},
                                            {"stable", i8},
                                            {"ns_per_frame_at_xpbd_error", f64},
                                            {"note", str}};
constexpr field challenge_verdict_fields[] = {{"criterion", str}, {"verdict", str}};
constexpr field small_steps_fields[] = {{"problem", str},      {"design", str},   {"n", i64},
                                        {"err_pos", f64},      {"link_err", f64}, {"work_per_frame", f64},
                                        {"ns_per_frame", f64}, {"diverged", i8}};

constexpr field_group runs_groups[] = {{run_fields}, {run_timing_fields, true}};
constexpr field_group substep_runs_groups[] = {{run_fields}, {run_timing_fields, true}, {substep_fields}};
constexpr field_group parameters_groups[] = {{parameter_fields}};
constexpr field_group equal_error_groups[] = {{equal_error_fields}};
constexpr field_group front_groups[] = {{front_fields}};
constexpr field_group limits_groups[] = {{limit_fields}};
constexpr field_group energy_groups[] = {{energy_fields}};
constexpr field_group loop_groups[] = {{loop_fields}};
constexpr field_group loop_cheapest_groups[] = {{loop_cheapest_fields}};
constexpr field_group substeps_verdict_groups[] = {{substeps_verdict_fields}};
constexpr field_group verdict_equal_error_groups[] = {{verdict_equal_error_fields}};
constexpr field_group frame_rate_groups[] = {{frame_rate_fields}};
constexpr field_group frame_answer_groups[] = {{frame_answer_fields}};
constexpr field_group frame_rate_run_groups[] = {{frame_rate_run_fields}};
constexpr field_group scan_point_groups[] = {{scan_point_fields}};
constexpr field_group scan_run_groups[] = {{scan_run_fields}};
constexpr field_group scan_best_groups[] = {{scan_best_fields}};
constexpr field_group challenge_entry_groups[] = {{challenge_entry_fields}};
constexpr field_group challenge_verdict_groups[] = {{challenge_verdict_fields}};
constexpr field_group small_steps_groups[] = {{small_steps_fields}};

constexpr table all_tables[] = {
    {"runs", "/problems/<p>/methods/<m>/runs", runs_groups},
    {"parameters", "/problems/<p>/parameters, /energy/<p>/parameters", parameters_groups},
    {"equal_error", "/problems/<p>/equal_error", equal_error_groups},
    {"front", "/problems/<p>/front_force_evals, /problems/<p>/front_time", front_groups},
    {"stability_limits", "/stability/limits", limits_groups},
    {"energy_summary", "/energy/<p>/summary", energy_groups},
    {"loop_runs", "/loop/<p>/<m>/runs", loop_groups},
    {"loop_cheapest", "/loop/<p>/<m>/cheapest", loop_cheapest_groups},
    {"substeps_runs", "/substeps/<p>/<m>/runs", substep_runs_groups},
    {"substeps_verdict", "/substeps/<p>/verdict", substeps_verdict_groups},
    {"verdict_equal_error", "/verdict/equal_error", verdict_equal_error_groups},
    {"verdict_frame_rate", "/verdict/frame_rate", frame_rate_groups},
    {"verdict_frame_answer", "/verdict/frame_answer", frame_answer_groups},
    {"frame_rate_runs", "/frame_rates/<p>/runs", frame_rate_run_groups},
    {"scan_points", "/scan/<name>/points", scan_point_groups},
    {"scan_runs", "/scan/<name>/runs", scan_run_groups},
    {"scan_best", "/scan/<name>/best", scan_best_groups},
    {"challenge_entries", "/challenge/entries", challenge_entry_groups},
    {"challenge_verdicts", "/challenge/verdicts", challenge_verdict_groups},
    {"small_steps", "/challenge/small_steps", small_steps_groups},
};

}  // namespace

std::string_view to_string(field_type t) {
  constexpr std::string_view names[] = {"f64", "i64", "i8", "str"};
  return names[static_cast<int>(t)];
}

std::span<const table> tables() { return all_tables; }

const table& find(std::string_view name) {
  for (const auto& t : all_tables)
    if (t.name == name) return t;
  throw std::logic_error("the study schema has no table named " + std::string(name));
}

std::string to_json(std::span<const table* const> own) {
  nlohmann::ordered_json out;
  out["format_version"] = format_version;
  out["row_incomplete_flags"] = row_incomplete_flags;
  for (const auto k : {method_kind::fixed_step, method_kind::adaptive})
    out["param_kind"][std::string(to_string(k))] = param_name(k);
  out["parameter_kinds"] = {"real", "whole", "named"};
  std::vector<const table*> every;
  for (const auto& t : all_tables) every.push_back(&t);
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

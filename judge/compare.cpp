#include "judge/compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string_view>
#include <tuple>

#include "core/number.hpp"
#include "core/text.hpp"
#include "core/work_precision.hpp"
#include "judge/rows.hpp"
#include "study/stability.hpp"

namespace stepbench {
namespace {

// ---------------------------------------------------------------------------------------
// The checks. Each takes a pair (the same problem, or the same method, in both files)
// and appends what it finds to the comparison. A new group of the study file is one more
// function in one of the two lists below.

struct problem_pair {
  const problem_study& base;
  const problem_study& next;
  const compare_options& opts;
};

struct method_pair {
  const problem_study& base_problem;
  const problem_study& next_problem;
  const method_study& base;
  const method_study& next;
  const compare_options& opts;
  std::vector<std::pair<std::size_t, std::size_t>> rows;  // (base row, new row) with equal param
};

// A finding not about one row (`method` empty for the problem itself).
change finding(change_kind k, std::string problem, std::string method, std::string what, compare_value old_value,
               compare_value new_value, double ratio = nan, std::string note = {}) {
  return {k, std::move(problem), std::move(method), "", nan, std::move(what), old_value, new_value, ratio, note};
}

// A finding about a row of NEW (`new_row`, its index).
change row_change(change_kind k, const method_pair& mp, std::size_t new_row, std::string what, double old_value,
                  double new_value, double ratio, std::string note) {
  change c = finding(k, mp.next_problem.name, mp.next.info.name, std::move(what), old_value, new_value, ratio, note);
  c.param_name = param_name(mp.next.info.kind);
  c.param = mp.next.rows[new_row].param;
  return c;
}

// Pairs the items of two lists by key: `both(b, n)` for each item of BASE that NEW has
// too; what only one side has is listed, as `presence_of(item, "BASE" or "NEW")` says.
template <class T, class Key, class Both, class Presence>
void pair_up(const std::vector<T>& base, const std::vector<T>& next, Key key, Both both, Presence presence_of,
             comparison& out) {
  const auto find = [&](const std::vector<T>& in, const T& x) {
    return std::find_if(in.begin(), in.end(), [&](const T& y) { return key(y) == key(x); });
  };
  for (const auto& b : base)
    if (const auto n = find(next, b); n != next.end())
      both(b, *n);
    else
      out.removed.push_back(presence_of(b, "BASE"));
  for (const auto& n : next)
    if (find(base, n) == base.end()) out.added.push_back(presence_of(n, "NEW"));
}

// The truth a problem's errors are measured against: its source and whether it is trusted.
void check_truth(const problem_pair& pp, comparison& out) {
  const truth_table &base = pp.base.truth, &next = pp.next.truth;
  if (base.source != next.source)
    out.changes.push_back(finding(change_kind::regression, pp.next.name, "", "truth_source", base.source, next.source));
  if (base.trusted != next.trusted)
    out.changes.push_back(finding(next.trusted ? change_kind::improvement : change_kind::regression, pp.next.name, "",
                                  "truth_trusted", base.trusted ? 1.0 : 0.0, next.trusted ? 1.0 : 0.0));
}

// The references: status (ok, failed, disagrees) and agreement with what they are compared with.
void check_references(const problem_pair& pp, comparison& out) {
  const auto both = [&](const reference_check& r, const reference_check& n) {
    const bool was_ok = r.status == "ok", is_ok = n.status == "ok";
    if (was_ok != is_ok)
      out.changes.push_back(finding(is_ok ? change_kind::improvement : change_kind::regression, pp.next.name, "",
                                    fmt::format("reference {} status", r.source), r.status, n.status, nan, n.reason));
    if (r.compared_with != n.compared_with) return;  // agreements with different things do not compare
    for (const auto& [field, old_rel, new_rel] :
         {std::tuple{"err_pos_rel", r.vs.pos_rel, n.vs.pos_rel}, std::tuple{"err_vel_rel", r.vs.vel_rel, n.vs.vel_rel}})
      if (const auto k = judge_agreement(old_rel, new_rel, pp.opts.error_factor))
        out.changes.push_back(finding(*k, pp.next.name, "", fmt::format("reference {} {}", r.source, field), old_rel,
                                      new_rel, new_rel / old_rel, fmt::format("vs {}", n.compared_with)));
  };
  pair_up(
      pp.base.truth.references, pp.next.truth.references, [](const reference_check& r) { return r.source; }, both,
      [&](const reference_check& r, const char* side) {
        return presence{pp.next.name, "", "reference " + r.source, fmt::format("status {} in {}", r.status, side)};
      },
      out);
}

// The ladder: rows are matched by their param, exactly. Rows only in BASE are removed,
// rows only in NEW added; a method whose kind changed has no rows in common.
void match_ladder(method_pair& mp, comparison& out) {
  const method_study &base = mp.base, &next = mp.next;
  if (base.info.kind != next.info.kind) {
    out.removed.push_back({mp.next_problem.name, next.info.name, "ladder",
                           fmt::format("was {} ({} rows), now {} ({} rows): no row compared", to_string(base.info.kind),
                                       base.rows.size(), to_string(next.info.kind), next.rows.size())});
    return;
  }
  for (std::size_t i = 0; i < base.rows.size(); ++i)
    for (std::size_t j = 0; j < next.rows.size(); ++j)
      if (base.rows[i].param == next.rows[j].param) {
        mp.rows.emplace_back(i, j);
        break;
      }
  // The rows of `m` whose param `other` lacks.
  const auto unmatched = [&](const method_study& m, const method_study& other, const char* side,
                             std::vector<presence>& to) {
    std::string params;
    std::size_t n = 0;
    for (const auto& r : m.rows)
      if (std::none_of(other.rows.begin(), other.rows.end(), [&](const method_row& o) { return o.param == r.param; }))
        params += (n++ ? ", " : "") + format_param(m.info.kind, r.param);
    if (n > 0)
      to.push_back({mp.next_problem.name, next.info.name, "ladder",
                    fmt::format("ladder changed: {} of {} rows only in {} ({}); {} compared", n, m.rows.size(), side,
                                params, mp.rows.size())});
  };
  unmatched(base, next, "BASE", out.removed);
  unmatched(next, base, "NEW", out.added);
}

// The observed order of a fixed-step method (the fit of err_pos_max against dt). On the
// same ladder it is always judged (the fit chooses its levels from the errors, so levels
// that moved are part of what changed). On different ladders (a quick study's shorter
// one) only where both fitted the same timesteps: otherwise its order is another
// measurement, not a change; and a change of fit status only on the same ladder.
void check_order(const method_pair& mp, comparison& out) {
  if (mp.base.info.kind != method_kind::fixed_step || mp.next.info.kind != method_kind::fixed_step) return;
  const bool same_ladder = mp.rows.size() == mp.base.rows.size() && mp.rows.size() == mp.next.rows.size();
  const fit_result &base = mp.base.fit, &next = mp.next.fit;
  const bool was = base.state == fit_result::status::fitted, is = next.state == fit_result::status::fitted;
  const auto fitted_params = [](const method_study& m) {  // the timesteps of its fitted levels
    std::vector<double> out;
    for (int level : m.fit.levels)
      if (level >= 0 && static_cast<std::size_t>(level) < m.rows.size()) out.push_back(m.rows[level].param);
    return out;
  };
  const auto add = [&](change_kind k, std::string what, compare_value old_value, compare_value new_value,
                       double ratio) {
    out.changes.push_back(finding(k, mp.next_problem.name, mp.next.info.name, what, old_value, new_value, ratio));
  };
  if (was && is) {
    if (!same_ladder && fitted_params(mp.base) != fitted_params(mp.next)) return;
    if (const auto k = judge_order(base.order, next.order, mp.opts.order_drop))
      add(*k, "observed order", base.order, next.order, next.order / base.order);
  } else if (same_ladder && (was || (is && base.state == fit_result::status::insufficient))) {
    // Fitted and no longer is; or could not be fitted and now is. (From `exact` to fitted
    // is no improvement: the errors left round-off, which the row checks judge.)
    add(was ? change_kind::regression : change_kind::improvement, "order fit", std::string(to_string(base.state)),
        std::string(to_string(next.state)), nan);
  }
}

// The flags that say a row has no result: diverged, failed, skipped over the work budget.
constexpr std::pair<const char*, bool run_metrics::*> row_flags[] = {
    {"diverged", &run_metrics::diverged}, {"failed", &run_metrics::failed}, {"skipped", &run_metrics::skipped}};

// Every row in both files: newly diverged, failed or skipped (or no longer), and each error.
void check_rows(const method_pair& mp, comparison& out) {
  const double pos_floor = error_floor_rel * std::max(mp.base_problem.truth.pos_scale, mp.next_problem.truth.pos_scale);
  const double vel_floor = error_floor_rel * std::max(mp.base_problem.truth.vel_scale, mp.next_problem.truth.vel_scale);
  for (const auto& [i, j] : mp.rows) {
    bool completed = true;
    const run_metrics &old_row = mp.base.rows[i].metrics, &new_row = mp.next.rows[j].metrics;
    for (const auto& [flag, member] : row_flags) {
      const double old_flag = old_row.*member, new_flag = new_row.*member;
      completed = completed && old_flag == 0 && new_flag == 0;
      if ((old_flag != 0) != (new_flag != 0))  // a flag: 0 -> 1 has no ratio
        out.changes.push_back(row_change(new_flag != 0 ? change_kind::regression : change_kind::improvement, mp, j,
                                         flag, old_flag, new_flag, nan, new_row.note));
    }
    if (!completed) continue;  // errors of completed runs only
    for (const char* metric : error_metrics) {
      const double old_err = metric_value(old_row, metric), new_err = metric_value(new_row, metric);
      const double floor = std::string_view(metric) == "err_vel_final" ? vel_floor : pos_floor;
      if (const auto k = judge_error(old_err, new_err, floor, mp.opts.error_factor))
        out.changes.push_back(row_change(*k, mp, j, metric, old_err, new_err, new_err / old_err, ""));
    }
  }
}

// Rows timed in both files: ratio, noise threshold, flag.
void collect_timing(const method_pair& mp, comparison& out) {
  const auto timed = [](const timing& t) {
    return std::isfinite(t.time_ns) && t.time_ns > 0 && t.repetitions >= 1 && !t.cut;
  };
  if (!out.timing_compared) return;
  for (const auto& [i, j] : mp.rows) {
    const timing &o = mp.base.rows[i].time, &n = mp.next.rows[j].time;
    if (!timed(o) || !timed(n)) continue;
    const double ratio = n.time_ns / o.time_ns, threshold = timing_threshold(o, n);
    out.timing.push_back({mp.next_problem.name, mp.next.info.name, std::string(param_name(mp.next.info.kind)),
                          mp.next.rows[j].param, o, n, ratio, threshold, judge_timing(ratio, threshold)});
  }
}

// Per method, over every problem: the geometric mean of its rows' ratios.
void summarize_timing(comparison& out) {
  std::map<std::string, std::tuple<timing_summary, std::set<std::string>, double>> by_method;  // problems, log sum
  for (const auto& t : out.timing) {
    auto& [s, problems, log_sum] = by_method[t.method];
    s.method = t.method;
    s.min_ratio = s.rows == 0 ? t.ratio : std::min(s.min_ratio, t.ratio);
    s.max_ratio = s.rows == 0 ? t.ratio : std::max(s.max_ratio, t.ratio);
    ++s.rows;
    s.slower += t.flag > 0;
    s.faster += t.flag < 0;
    problems.insert(t.problem);
    log_sum += std::log(t.ratio);
  }
  for (auto& [name, m] : by_method) {
    auto& [s, problems, log_sum] = m;
    s.problems = problems.size();
    s.geomean = std::exp(log_sum / static_cast<double>(s.rows));
    out.timing_summaries.push_back(s);
  }
}

using method_check = void (*)(const method_pair&, comparison&);
constexpr method_check method_checks[] = {check_order, check_rows, collect_timing};

// The methods of a problem: present in one file only, or compared by every method check.
void check_methods(const problem_pair& pp, comparison& out) {
  pair_up(
      pp.base.methods, pp.next.methods, [](const method_study& m) { return m.info.name; },
      [&](const method_study& m, const method_study& n) {
        method_pair mp{pp.base, pp.next, m, n, pp.opts, {}};
        match_ladder(mp, out);
        for (const auto check : method_checks) check(mp, out);
      },
      [&](const method_study& m, const char*) {
        return presence{pp.next.name, m.info.name, "method",
                        fmt::format("{}, {} rows", to_string(m.info.kind), m.rows.size())};
      },
      out);
}

using problem_check = void (*)(const problem_pair&, comparison&);
constexpr problem_check problem_checks[] = {check_truth, check_references, check_methods};

// ---------------------------------------------------------------------------------------
// What differs between the files besides the results.

std::string number(double v) { return fmt::format("{:.12g}", v); }

void root_differences(const study_record& base, const study_record& next, comparison& out) {
  // Run-specific figures that always differ are left out, and `sweep_options`, the
  // options as a block of lines for `stepbench merge`: the settings that shape results
  // have attributes of their own (levels, tolerances, ...), and --set shows as parameters.
  const std::set<std::string> skip{"created_utc", "wall_seconds", "benchmark_wall_seconds", "sweep_options"};
  // Machine, build and mode first: they decide whether the timings compare at all.
  const std::vector<std::string> first{
      "cpu",        "cores",      "num_cpus",      "mhz_per_cpu", "cpu_scaling_enabled",
      "compiler",   "build_type", "dependencies",  "build_flags", "version",
      "git_commit", "timing",     "benchmark_mode"};
  std::map<std::string, std::pair<std::string, std::string>> all;
  const auto gather = [&](const study_record& s, bool is_new) {
    for (const auto& [k, v] : s.meta) (is_new ? all[k].second : all[k].first) = v;
    for (const auto& [k, v] : s.settings) (is_new ? all[k].second : all[k].first) = number(v);
  };
  gather(base, false);
  gather(next, true);
  std::vector<std::string> order(first);
  for (const auto& [k, v] : all)
    if (std::find(first.begin(), first.end(), k) == first.end()) order.push_back(k);
  for (const auto& k : order) {
    const auto it = all.find(k);
    if (it == all.end() || skip.count(k) || it->second.first == it->second.second) continue;
    const auto shown = [](const std::string& v) { return v.empty() ? std::string("(absent)") : v; };
    out.differences.push_back({k, shown(it->second.first), shown(it->second.second)});
  }
}

// A problem's parameters (and the scales derived from its truth), equal to 1e-9 relative.
void problem_differences(const problem_study& base, const problem_study& next, comparison& out) {
  std::set<std::string> keys;
  for (const auto& [k, v] : base.params) keys.insert(k);
  for (const auto& [k, v] : next.params) keys.insert(k);
  for (const auto& k : keys) {
    const auto b = base.params.find(k), n = next.params.find(k);
    const bool in_b = b != base.params.end(), in_n = n != next.params.end();
    if (in_b && in_n) {
      const double x = b->second, y = n->second;
      if (x == y || std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y)) || (std::isnan(x) && std::isnan(y)))
        continue;
    }
    out.differences.push_back({fmt::format("{}: {}", next.name, k), in_b ? number(b->second) : "(absent)",
                               in_n ? number(n->second) : "(absent)"});
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------

double spread(const timing& t) { return t.repetitions >= 2 ? (t.time_ns_max - t.time_ns_min) / t.time_ns : nan; }

std::optional<change_kind> judge_error(double old_err, double new_err, double floor, double factor) {
  if (std::isnan(old_err) && std::isnan(new_err)) return std::nullopt;
  if (!std::isfinite(new_err) && std::isfinite(old_err)) return change_kind::regression;
  if (std::isfinite(new_err) && !std::isfinite(old_err)) return change_kind::improvement;
  if (new_err > floor && new_err > factor * old_err) return change_kind::regression;
  if (old_err > floor && old_err > factor * new_err) return change_kind::improvement;
  return std::nullopt;
}

std::optional<change_kind> judge_agreement(double old_rel, double new_rel, double factor) {
  if (!std::isfinite(old_rel) || !std::isfinite(new_rel)) return std::nullopt;  // not compared
  return judge_error(old_rel, new_rel, agreement_floor, factor);
}

std::optional<change_kind> judge_order(double old_order, double new_order, double drop) {
  if (!std::isfinite(old_order) || !std::isfinite(new_order)) return std::nullopt;
  if (new_order < old_order - drop) return change_kind::regression;
  if (new_order > old_order + drop) return change_kind::improvement;
  return std::nullopt;
}

double timing_threshold(const timing& old_time, const timing& new_time) {
  const bool both_spread = old_time.repetitions >= 2 && new_time.repetitions >= 2;
  double t = both_spread ? timing_noise_floor : timing_single_run_floor;
  for (const auto& s : {old_time, new_time})
    if (std::isfinite(spread(s))) t = std::max(t, timing_spread_multiple * spread(s));
  return t;
}

int judge_timing(double ratio, double threshold) {
  if (ratio > 1.0 + threshold) return 1;
  if (ratio < 1.0 / (1.0 + threshold)) return -1;
  return 0;
}

std::vector<std::string> describe_thresholds(const compare_options& o) {
  return {
      fmt::format(
          "An error (err_pos_max, err_pos_final, err_pos_rms, err_vel_final) of a row that completed in both "
          "files regresses when it grows by more than {:g}x (--error-factor) while the new error is above the "
          "round-off floor {:g} x pos_scale for position errors, {:g} x vel_scale for err_vel_final (the larger "
          "scale of the two files); it improves when it shrinks by as much from above the floor.",
          o.error_factor, error_floor_rel, error_floor_rel),
      "A row that newly diverges, fails or is skipped (over the work budget) regresses; one that no longer does "
      "improves.",
      fmt::format("An observed order (fit_slope of a fixed-step method fitted in both) regresses when it drops by more "
                  "than {:g} (--order-drop), or when it was fitted and no longer is; it improves when it rises by as "
                  "much.",
                  o.order_drop),
      fmt::format("A reference regresses when its status leaves ok or its agreement (err_pos_rel, err_vel_rel) grows "
                  "by more than {:g}x above {:g}; a problem regresses when its truth_source changes or its truth "
                  "is no longer trusted.",
                  o.error_factor, agreement_floor),
      fmt::format("A stability limit of our methods (/stability, from the amplification matrix) regresses when it "
                  "moves by more than {:g} %, or when a method becomes or stops being unstable for every dt or "
                  "unconditionally stable.",
                  100 * stability_tolerance),
      fmt::format("Only what both files hold is compared: what only BASE has (a problem, a method, a reference, "
                  "rows of a ladder) {}; what only NEW has is listed as added.",
                  o.require_base ? "regresses (--require-base)" : "is listed as removed, not a regression"),
      fmt::format("Timing: a row timed in both is flagged when new/old exceeds 1+t (slower) or falls below "
                  "1/(1+t) (faster), t = max({:g} %, {:g} x the larger (max - min)/median of the two files' "
                  "repetitions); with a single repetition on a side there is no spread, and the floor is {:g} % "
                  "instead of {:g} %. {}",
                  100 * timing_noise_floor, timing_spread_multiple, 100 * timing_single_run_floor,
                  100 * timing_noise_floor,
                  o.gate_timing ? "A flagged slowdown regresses (--gate-timing)."
                                : "Timing informs; it gates only with --gate-timing."),
  };
}

std::size_t comparison::count(change_kind k) const {
  return std::ranges::count_if(changes, [k](const change& c) { return c.kind == k; });
}
std::size_t comparison::slower() const {
  return std::ranges::count_if(timing, [](auto& r) { return r.flag > 0; });
}
std::size_t comparison::faster() const {
  return std::ranges::count_if(timing, [](auto& r) { return r.flag < 0; });
}
std::size_t comparison::gating() const {
  return count(change_kind::regression) + (options.require_base ? removed.size() : 0) +
         (options.gate_timing ? slower() : 0);
}

// The stability limits of our methods (/stability): a limit that moves by more than
// stability_tolerance (relative), or a method that becomes (or stops being) stable for
// every dt or unstable for every dt, is a regression.
void check_stability(const study& base_study, const study& next_study, comparison& out) {
  const auto& next = next_study.results.get<stability_data>().limits;
  const auto flags = [](const stability_limit& l) {
    return std::string(l.unconditionally_stable ? "unconditionally stable"
                       : l.unstable_for_all_dt  ? "unstable for every dt"
                                                : "finite limit");
  };
  for (const auto& b : base_study.results.get<stability_data>().limits) {
    const auto it = std::find_if(next.begin(), next.end(),
                                 [&](const auto& n) { return n.integrator == b.integrator && n.test == b.test; });
    const std::string test(to_string(b.test));
    if (it == next.end()) {
      if (!next.empty()) out.removed.push_back({"stability", b.integrator, "limit " + test, "in BASE only"});
    } else if (flags(b) != flags(*it)) {
      out.changes.push_back(
          finding(change_kind::regression, "stability", b.integrator, test + " stability", flags(b), flags(*it)));
    } else if (std::isfinite(b.theory) && std::isfinite(it->theory) &&
               std::abs(it->theory / b.theory - 1.0) > stability_tolerance) {
      out.changes.push_back(finding(change_kind::regression, "stability", b.integrator,
                                    test + " stability limit (y = w dt or lambda dt)", b.theory, it->theory,
                                    it->theory / b.theory));
    }
  }
}

comparison compare_studies(const study& base, const study& next, const compare_options& opts) {
  if (!(opts.error_factor >= 1.0) || !std::isfinite(opts.error_factor))
    throw std::invalid_argument(
        fmt::format("--error-factor must be a finite number >= 1, got {:g}", opts.error_factor));
  if (!(opts.order_drop >= 0.0) || !std::isfinite(opts.order_drop))
    throw std::invalid_argument(fmt::format("--order-drop must be a finite number >= 0, got {:g}", opts.order_drop));
  if (!base.record || !next.record) throw std::logic_error("compare_studies takes studies read from files");
  const study_record &base_file = *base.record, &next_file = *next.record;
  if (base_file.format_version != next_file.format_version)
    throw std::runtime_error(
        fmt::format("cannot compare '{}' (format_version {}) with '{}' (format_version {}): "
                    "different study formats",
                    base_file.path, base_file.format_version, next_file.path, next_file.format_version));
  comparison out;
  out.options = opts;
  out.base_path = base_file.path;
  out.new_path = next_file.path;
  out.base_meta = base_file.meta;
  out.new_meta = next_file.meta;
  out.base_timed = base.timed.has_value();
  out.new_timed = next.timed.has_value();
  out.timing_compared = out.base_timed && out.new_timed;
  if (!out.timing_compared)
    out.timing_note = !out.base_timed && !out.new_timed ? "neither file is timed"
                      : out.base_timed                  ? "NEW is not timed"
                                                        : "BASE is not timed";
  root_differences(base_file, next_file, out);
  if (out.timing_compared) {
    std::string differ;
    for (const auto& d : out.differences)
      for (const char* k : {"cpu", "cores", "compiler", "build_type", "build_flags", "dependencies", "benchmark_mode"})
        if (d.what == k) differ += (differ.empty() ? "" : ", ") + d.what;
    if (!differ.empty()) out.timing_note = fmt::format("the files differ in {}: the ratios measure that too", differ);
  }
  pair_up(
      base.problems, next.problems, [](const problem_study& p) { return p.name; },
      [&](const problem_study& b, const problem_study& n) {
        problem_differences(b, n, out);
        const problem_pair pp{b, n, opts};
        for (const auto check : problem_checks) check(pp, out);
      },
      [](const problem_study& p, const char*) {
        return presence{p.name, "", "problem", plural(p.methods.size(), "method", "methods")};
      },
      out);
  check_stability(base, next, out);
  summarize_timing(out);
  return out;
}

}  // namespace stepbench

#include "judge/outcome.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

#include "core/method.hpp"
#include "study/substeps.hpp"

namespace stepbench {

namespace {

// The parameters of the failed rows: up to four named, else their range.
std::string failed_params(std::string_view label, const std::vector<double>& params) {
  std::string out;
  if (params.size() <= 4)
    for (std::size_t i = 0; i < params.size(); ++i) out += fmt::format("{}{:.3g}", i ? ", " : "", params[i]);
  else
    out = fmt::format("{:.3g} to {:.3g}", params.front(), params.back());
  return fmt::format("{} {}", label, out);
}

// What kind of failure a reason names: its opening words, up to the first ':' (the
// scene's report: "the orbit collapsed", "at periapsis") once a leading "<method>: " is
// dropped, or up to " at t" / " to t" (a solver's symptom without a scene report).
std::string reason_kind(std::string_view method, std::string_view note) {
  if (note.substr(0, method.size()) == method && note.substr(method.size(), 2) == ": ")
    note.remove_prefix(method.size() + 2);
  std::size_t end = note.find(':');
  for (const char* tail : {" at t", " to t"}) end = std::min(end, note.find(tail));
  return std::string(note.substr(0, end));
}

// The failed rows of a method, each (param, metrics).
using failed_rows = std::vector<std::pair<double, const run_metrics*>>;

// "implicit_euler: 8 of 12 failed on kepler at dt 0.0368 to 0.000288: the orbit collapsed
// (5), at periapsis (3); at dt 0.000288: <its whole reason>": the kinds with their counts,
// then the reason at the finest parameter in full.
std::string failure_line(std::string_view method, std::string_view where, std::string_view label,
                         const failed_rows& failed, std::size_t rows) {
  std::vector<std::pair<std::string, int>> kinds;
  std::vector<double> params;
  for (const auto& [param, m] : failed) {
    params.push_back(param);
    const std::string k = reason_kind(method, m->note);
    auto it = std::find_if(kinds.begin(), kinds.end(), [&](const auto& e) { return e.first == k; });
    if (it == kinds.end())
      kinds.emplace_back(k, 1);
    else
      ++it->second;
  }
  std::string counted;
  for (const auto& [k, n] : kinds) counted += fmt::format("{}{} ({})", counted.empty() ? "" : ", ", k, n);
  return fmt::format("{}: {} of {} failed on {} at {}: {}; at {} {:.3g}: {}", method, failed.size(), rows, where,
                     failed_params(label, params), counted, label, params.back(), failed.back().second->note);
}

}  // namespace

// The runs that failed (a solver error, a non-converging Newton iteration), summed up one
// line per method and problem on stderr, and counted. Diverged and skipped runs are
// outcomes the study records, not failures; a problem without a trusted truth is
// reported as such instead.
int report_study_outcome(const study& s, const char* program, bool strict) {
  std::size_t failed = 0;
  const auto report = [&](std::string_view method, const std::string& where, std::string_view label,
                          const failed_rows& rows, std::size_t total) {
    if (rows.empty()) return;
    failed += rows.size();
    std::fprintf(stderr, "%s: %s\n", program, failure_line(method, where, label, rows, total).c_str());
  };
  std::string untrusted;
  for (const auto& ps : s.problems) {
    if (!ps.truth.trusted) {
      untrusted += (untrusted.empty() ? "" : ", ") + ps.name;
      continue;
    }
    for (const auto& ms : ps.methods) {
      failed_rows rows;
      for (const auto& r : ms.rows)
        if (r.metrics.failed) rows.emplace_back(r.param, &r.metrics);
      report(ms.info.name, ps.name, param_name(ms.info.kind), rows, ms.rows.size());
    }
  }
  for (const auto& st : s.results.get<std::vector<substep_study>>())
    for (const auto& m : st.methods) {
      failed_rows rows;
      for (const auto& r : m.rows)
        if (r.row.metrics.failed) rows.emplace_back(r.substeps, &r.row.metrics);
      report(m.info.name, fmt::format("the substeps study of {}", st.problem), "substeps", rows, m.rows.size());
    }
  // Every other problem has been measured and written; only then is a problem without a
  // trusted truth an error.
  if (!untrusted.empty()) {
    std::fprintf(stderr, "%s: error: no trusted truth for %s (errors recorded as NaN)\n", program, untrusted.c_str());
    return 1;
  }
  if (failed > 0) {
    std::fprintf(stderr, "%s: %zu case%s failed, each recorded with its reason in the study file%s\n", program, failed,
                 failed == 1 ? "" : "s",
                 strict ? " (--strict: exit 3)" : ": findings of the study, not errors of the run");
    if (strict) return exit_failed_cases;
  }
  return 0;
}

}  // namespace stepbench

#include "judge/outcome.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

#include "core/method.hpp"
#include "study/substeps.hpp"

namespace stepbench {

std::vector<std::string> failed_cases(const study& s) {
  std::vector<std::string> out;
  for (const auto& ps : s.problems) {
    if (!ps.truth.trusted) continue;
    for (const auto& ms : ps.methods)
      for (const auto& r : ms.rows)
        if (r.metrics.failed)
          out.push_back(fmt::format("{}/{} at {} {:g}: {}", ps.name, ms.info.name, param_name(ms.info.kind), r.param,
                                    r.metrics.note));
  }
  for (const auto& st : s.results.get<std::vector<substep_study>>())
    for (const auto& m : st.methods)
      for (const auto& r : m.rows)
        if (r.row.metrics.failed)
          out.push_back(
              fmt::format("substeps/{}/{} at n = {}: {}", st.problem, m.info.name, r.substeps, r.row.metrics.note));
  return out;
}

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

// "implicit_euler: 8 of 12 failed on kepler at dt 0.0368 to 0.000288: the orbit collapsed
// (5), at periapsis (3); at dt 0.000288: <its whole reason>": the kinds with their counts,
// then the reason at the finest parameter in full.
std::string failure_line(std::string_view method, std::string_view where, std::string_view label,
                         const std::vector<const run_metrics*>& failed, const std::vector<double>& params,
                         std::size_t rows) {
  std::vector<std::pair<std::string, int>> kinds;
  for (const auto* m : failed) {
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
                     failed_params(label, params), counted, label, params.back(), failed.back()->note);
}

}  // namespace

std::vector<std::string> failure_summary(const study& s) {
  std::vector<std::string> out;
  for (const auto& ps : s.problems) {
    if (!ps.truth.trusted) continue;
    for (const auto& ms : ps.methods) {
      std::vector<const run_metrics*> failed;
      std::vector<double> params;
      for (const auto& r : ms.rows)
        if (r.metrics.failed) {
          failed.push_back(&r.metrics);
          params.push_back(r.param);
        }
      if (!failed.empty())
        out.push_back(failure_line(ms.info.name, ps.name, param_name(ms.info.kind), failed, params, ms.rows.size()));
    }
  }
  for (const auto& st : s.results.get<std::vector<substep_study>>())
    for (const auto& m : st.methods) {
      std::vector<const run_metrics*> failed;
      std::vector<double> params;
      for (const auto& r : m.rows)
        if (r.row.metrics.failed) {
          failed.push_back(&r.row.metrics);
          params.push_back(static_cast<double>(r.substeps));
        }
      if (!failed.empty())
        out.push_back(failure_line(m.info.name, fmt::format("the substeps study of {}", st.problem), "substeps", failed,
                                   params, m.rows.size()));
    }
  return out;
}

int report_study_outcome(const study& s, const char* program, bool strict) {
  const auto failed = failed_cases(s);
  for (const auto& line : failure_summary(s)) std::fprintf(stderr, "%s: %s\n", program, line.c_str());
  // Every other problem has been measured and written; only then is a problem without a
  // trusted truth an error.
  if (const auto bad = untrusted_problems(s); !bad.empty()) {
    std::string names;
    for (const auto& b : bad) names += (names.empty() ? "" : ", ") + b;
    std::fprintf(stderr, "%s: error: no trusted truth for %s (errors recorded as NaN)\n", program, names.c_str());
    return 1;
  }
  if (!failed.empty()) {
    std::fprintf(stderr, "%s: %zu case%s failed, each recorded with its reason in the study file%s\n", program,
                 failed.size(), failed.size() == 1 ? "" : "s",
                 strict ? " (--strict: exit 3)" : ": findings of the study, not errors of the run");
    if (strict) return exit_failed_cases;
  }
  return 0;
}

std::vector<std::string> untrusted_problems(const study& s) {
  std::vector<std::string> out;
  for (const auto& ps : s.problems)
    if (!ps.truth.trusted) out.emplace_back(ps.name);
  return out;
}

}  // namespace stepbench

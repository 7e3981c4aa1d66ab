#pragma once
// The outcome of a study's runs, as a command says it at its end: the failed runs (a
// method's finding, recorded with its reason) and the problems without a trusted truth.
#include <string>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// Problems whose truth is not trusted (no closed form, no two references agreeing).
std::vector<std::string> untrusted_problems(const study& s);

// The runs that failed (a solver error, a non-converging Newton iteration), one line
// each: "<problem>/<method> at <dt or tol>: <reason>". Diverged and skipped runs are
// outcomes the study records, not failures; a problem without a trusted truth is
// reported by untrusted_problems instead.
std::vector<std::string> failed_cases(const study& s);

// The failed runs summed up, one line per method and problem: "implicit_euler: 8 of 12
// failed on kepler at dt 0.0368 to 0.000288: the orbit collapsed (5), at periapsis (3);
// at dt 0.000288: <the whole reason of the finest>".
std::vector<std::string> failure_summary(const study& s);

// The exit status of a command that ran the study and wrote it: 0 the study is written
// whole (a method that failed on a case is a finding, recorded with its reason, and
// summed up on stderr, one line per method and problem); 1 a problem has no trusted
// truth; with `strict`, 3 when some case failed.
inline constexpr int exit_failed_cases = 3;
int report_study_outcome(const study& s, const char* program, bool strict = false);

}  // namespace stepbench

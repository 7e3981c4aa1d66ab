#pragma once
// The outcome of a study's runs, as a command says it at its end: the failed runs (a
// method's finding, recorded with its reason) and the problems without a trusted truth.
#include "study/study.hpp"

namespace stepbench {

// The exit status of a command that ran the study and wrote it: 0 the study is written
// whole (a method that failed on a case is a finding, recorded with its reason, and
// summed up on stderr, one line per method and problem); 1 a problem has no trusted
// truth; with `strict`, 3 when some case failed.
inline constexpr int exit_failed_cases = 3;
int report_study_outcome(const study& s, const char* program, bool strict = false);

}  // namespace stepbench

#pragma once
// A scan's range answer: the cheapest method and substeps stable everywhere and within
// the tolerance wherever there is a truth.
#include <map>
#include <string>

#include "study/scan.hpp"
#include "study/study.hpp"

namespace stepbench {

scan_answer answer_scan(const scan_result& scan, double tol);

// Each of our fixed-step methods' ns per force evaluation on `problem`, measured by the
// benchmark in a timed study (the median over its timed rows of time / force evaluations,
// as judge/loop.hpp's step cost is of time / steps): a scan's ranking cost
// (scan_options::ns_per_force_eval), so it ranks as `advise --hz` does on that study.
// Empty when the study is untimed or lacks the problem.
std::map<std::string, double> measured_eval_costs(const study& s, const std::string& problem);

// A scene named by its parameters, so an answer says which scene it is for: "masses = 32,
// k_s = 10000 N/m, ...", every declared parameter of `problem` at its value in `values`
// (else its default), each in `set` marked "(set)".
std::string scene_text(const std::string& problem, const std::map<std::string, double>& values,
                       const std::map<std::string, double>& set = {});

}  // namespace stepbench

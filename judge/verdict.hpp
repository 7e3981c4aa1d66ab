#pragma once
// The verdict (study/verdict.hpp says what it answers), judged from the study as it holds
// it, and the findings generated from it and the other parts' results.
#include <string>
#include <vector>

#include "study/study.hpp"

namespace stepbench {

// The error metric the verdict ranks by.
inline constexpr const char* verdict_metric = "err_pos_max";

verdict_tables compute_verdict(const study& s);

finding_inputs finding_inputs_of(const study& s);
// The substep pair the findings quote: the lecture's backward Euler (implicit, first
// order, not symplectic) against symplectic Euler (explicit, first order), picked by
// their registry entries' order and capabilities, not their names.
bool is_first_order_pair(const substep_verdict& sv);
std::vector<std::string> findings_of(const verdict_tables& v, const finding_inputs& in);

// The cost of a frame of a frame-rate run: the benchmark's median ns per step of its
// method on the problem (`ps`, nullptr: none) times the steps of a frame when `timed`,
// else the force evaluations of a frame.
double cost_per_frame(const problem_study* ps, const frame_rate_study& fs, const frame_rate_run& r, bool timed);
// A problem's frame-rate runs as the file stores them and `advise --hz` ranks them: each
// with its cost a frame (cost_per_frame, from the study's sweep of the problem).
std::vector<frame_option> frame_options(const study& s, const frame_rate_study& fs);

verdict_agreement compare_verdicts(const verdict_tables& base, const verdict_tables& next);
}  // namespace stepbench

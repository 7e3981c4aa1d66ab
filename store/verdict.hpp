#pragma once
// /verdict and /frame_rates of a study file (docs/study-format.md): written from the
// study, and the verdict read back.
#include <string>
#include <vector>

#include "store/h5.hpp"
#include "study/study.hpp"

namespace stepbench {

// /verdict, as judged into the study (nothing when it holds no verdict), and
// /frame_rates/<problem> (docs/study-format.md).
void write_verdict(H5::Group& root, const study& s);
void write_frame_rates(H5::Group& root, const study& s);

// /verdict read back from a study file's root (the verdict part's read, merge's judging
// again); throws std::runtime_error naming what is missing, without the path.
verdict_tables read_verdict(const H5::Group& root);

// /frame_rates read back (the frame_rates part's read): each problem's runs.
void read_frame_rates(const H5::Group& root, study& s);

// The findings, which span problems, judged again from a merged file's joined tables
// (/verdict's attribute `findings`): merge's judged_again for the verdict part.
void judge_findings_again(H5::Group& root, const std::vector<std::string>& problems);

// The tables of /verdict and /frame_rates, in the schema's order (store/schema.cpp).
std::vector<schema::table> verdict_file_tables();

}  // namespace stepbench

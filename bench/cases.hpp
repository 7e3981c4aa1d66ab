#pragma once
// The timed cases: one Google Benchmark case per row of the study that completed (a run
// that diverged, failed or was skipped has nothing worth timing), registered at run time
// from the study's own entries, each one whole integration over the horizon. Names:
// <problem>/<method>/dt:<dt> or <problem>/<method>/tol:<tol>, and
// substeps/<problem>/<method>/n:<substeps> for the small-steps comparison. The accuracy counters come
// from the row the sweep measured; the case only times. Results are matched back to
// rows by the name each case was registered under, never re-formatted from a row.
#include <map>
#include <string>
#include <vector>

#include "run/sweep.hpp"

namespace stepbench::bench {

struct timed_case {
  std::string name;    // as registered
  std::string family;  // <problem>/<method>: the time budget is per family
  method_row* row = nullptr;
  std::vector<double> ns_per_run;  // one entry per repetition
  std::string skipped;             // SkipWithError message, if any
};

class case_book {
 public:
  explicit case_book(double case_budget_s) : budget_s_(case_budget_s) {}
  // Registers every case of the study (which must outlive the benchmark run).
  void register_all(study& s);
  timed_case* find(const std::string& registered_name);
  // Copies the timings into the rows: the median, fastest and slowest repetition.
  void merge_into_rows();
  std::size_t timed_count() const;

 private:
  // Called before a case runs: true when its family's previous (coarser) case took more
  // than half the budget per run, so this one (about twice the work) would exceed it.
  // Google Benchmark calls a case several times while it sizes the iteration count;
  // those calls of the same case do not count against it.
  bool over_budget(const timed_case& c) const;
  // Registers the case of one completed row.
  void add(const problem_study& ps, const method_info& info, method_row& row, std::string name, std::string family);
  void record(const timed_case& c, double ns);

  double budget_s_;
  std::vector<std::unique_ptr<timed_case>> cases_;
  std::map<std::string, timed_case*> by_name_;
  std::map<std::string, std::pair<const timed_case*, double>> family_last_;  // last case and its slowest run
};

}  // namespace stepbench::bench

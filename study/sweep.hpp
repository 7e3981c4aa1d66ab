#pragma once
// The study: every selected method (ours, the peers, the baseline) on every selected
// problem, over a halving ladder of timesteps (fixed-step methods) or a ladder of
// tolerances (adaptive ones), each run measured against the truth by the same code,
// with the observed order fitted. The benchmark adds timings to these rows.
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <typeindex>
#include <vector>

#include "core/convergence_fit.hpp"
#include "core/measure.hpp"
#include "core/method.hpp"
#include "registry/registry.hpp"
#include "study/challenge.hpp"
#include "study/energy.hpp"
#include "study/loop.hpp"
#include "study/method_row.hpp"
#include "study/scan.hpp"
#include "study/stability.hpp"

namespace stepbench {

// 10^-first, 10^-(first + stride), ... down to 10^-last: the tolerance ladder and the
// equal-error targets (study_file.hpp) are both decades, built here.
std::vector<double> decades(int first, int last, int stride);
// Relative tolerances of the adaptive methods: 1e-2 .. 1e-14, down to round-off, so that
// every equal-error target (1e-2 .. 1e-12) is reachable (every other one when
// `thinned`).
std::vector<double> tolerance_ladder(bool thinned = false);

struct substep_options {
  std::vector<std::string> problems{"stiff_spring", "spring_chain", "n_pendulum"};
  // xpbd's n substeps of one constraint pass: the method the Small Steps paper is about.
  std::vector<std::string> explicit_methods{"semi_implicit_euler", "velocity_verlet", "xpbd"};
  std::vector<std::string> implicit_methods{"implicit_euler", "implicit_midpoint"};
  std::vector<int> counts{1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
  int frames = 32;  // the frame is horizon / frames; the truth's sample times are its ends
};

// The frame-rate study (study/verdict.hpp): our fixed-step methods at whole frames of
// each rate, with n substeps a frame.
struct frame_rate_options {
  std::vector<double> hz{30, 60, 120, 240};  // each divides the largest, so one truth serves all
  std::vector<int> substeps{1, 2, 4, 8, 16, 32, 64};
};

struct sweep_options {
  // The parts of the study to run (parts/part.hpp), by name, in any order; empty: every
  // part. The sweep's rows are the part every other reads: a selection without it runs
  // only parts that need no rows (stability, energy, scans, challenge).
  std::vector<std::string> parts;
  std::vector<std::string> problems;  // empty: all
  std::vector<std::string> methods;   // empty: all that run on each problem
  // Parameter overrides per problem: overrides["pendulum"]["theta0_deg"] = 30.
  std::map<std::string, std::map<std::string, double>> overrides;
  int levels = 12;  // dt ladder length every fixed-step method runs (at least 8 for the default study)
  // Beyond `levels` the ladder goes on halving, up to `max_levels`, while the error still
  // falls by more than `round_off_fall` a level and the next level fits the work budget:
  // each method is followed to its round-off (or to the budget), not cut at one step count.
  int max_levels = 20;
  double round_off_fall = 1.5;
  int base_steps = 32;    // steps at the coarsest level; dt_k = T / (base_steps 2^k)
  int sample_count = 32;  // fixed sample times j T / sample_count; must divide base_steps
  std::vector<double> tolerances = tolerance_ladder();
  reference_tolerances tol{};
  run_limits limits{};                                // the work budget of one run (core/method.hpp)
  substep_options substeps{};                         // the small-steps comparison (study/substeps.hpp)
  loop_options loop{};                                // the game-loop study (study/loop.hpp)
  energy_options energy{};                            // the long-run energy study (study/energy.hpp)
  frame_rate_options frame_rates{};                   // the game programmer's frame-rate table (study/verdict.hpp)
  std::vector<scan_options> scans = default_scans();  // parameter scans (study/scan.hpp), under /scan
  challenge_options challenge{};  // the pendulum challenge and Small Steps (study/challenge.hpp), with n_pendulum
  bool progress = false;          // one line per problem on stderr
  int jobs = 0;                   // threads the problems are swept on (0: one a core)
  // --shard K/N: this run takes shard `shard_index` (0-based) of `shard_count`, a
  // deterministic share of the selected problems balanced by their counted cost
  // (sweep_shard), with every part of the study that belongs to those problems.
  int shard_index = 0, shard_count = 1;
  // A caller's live progress: called after each problem and each later study (frame
  // rates, loop, energy) with the parts done and the total (sweep_parts); and where the
  // sweep's warnings go (a reference that disagrees), so that they do not land on a
  // progress line drawn in place. Unset: warnings to stderr, no progress calls.
  std::function<void(std::size_t done, std::size_t total)> on_progress;
  std::function<void(const std::string&)> on_warning;
};

// The problems the options select, in the study's order: opts.problems, or every problem.
std::vector<std::string> selected_problems(const sweep_options& opts);

// The counted cost of sweeping a problem, computable without running it: its coordinates
// x the fixed-step ladder's steps over the first `levels` levels (base_steps (2^levels -
// 1)) x the methods that run on it (an adaptive method counted as one such ladder), plus
// its reference solves' predicted work (core/measure.hpp predicted_reference_work, in
// coordinate evaluations: x reference_work_in_evaluations).
double sweep_cost(const std::string& problem, const sweep_options& opts);

// The selected problems of shard k of n (0-based), in the study's order: largest counted
// cost first (ties in the study's order), each to the shard with the least cost so far
// (ties to the lowest shard). Deterministic: every machine computes the same split, and a
// shard may hold no problem (n above the selected problems).
std::vector<std::string> sweep_shard(const sweep_options& opts, int k, int n);
// The problems this run sweeps: sweep_shard(opts, opts.shard_index, opts.shard_count).
std::vector<std::string> shard_problems(const sweep_options& opts);

// The threads run_sweep uses for `problems` problems (opts.jobs, 0: one a core).
int sweep_jobs(const sweep_options& opts, std::size_t problems);

struct method_study {
  method_info info;
  std::vector<method_row> rows;
  fit_result fit;                 // against dt (fixed-step) or against the tolerance (adaptive)
  int declared_order_holds = -1;  // see core/convergence_fit.hpp
  std::string ladder_end;         // why the ladder stopped after its last row
};

struct problem_study {
  std::unique_ptr<problem_instance> problem;
  double horizon = 0.0;
  truth_table truth;
  std::vector<method_study> methods;
};

// How the timings were taken (present only when the study was timed).
struct timing_settings {
  std::string mode;  // "quick" or "full"
  double min_time_s = 0.0;
  int repetitions = 1;
  double case_budget_s = 0.0;
  int num_cpus = 0;
  double mhz_per_cpu = 0.0;
  int cpu_scaling_enabled = -1;  // 1 on, 0 off, -1 unknown (Google Benchmark's context)
  double wall_seconds = 0.0;
};

struct substep_row {
  int substeps = 1;
  method_row row;              // param = dt = frame / substeps
  double extra_damping = 0.0;  // max_j (E_true - E) / energy_scale; NaN without energy or when not completed
};

struct substep_method {
  method_info info;
  std::vector<substep_row> rows;
};

struct substep_study {
  std::string problem;
  double frame_dt = 0.0;
  std::vector<substep_method> methods;
};

struct frame_rate_run {
  double hz = 0.0;
  std::string method;
  int substeps = 1;
  method_row row;  // param = dt = 1 / (hz substeps); errors at the frame ends
};

struct frame_rate_study {
  std::string problem, unit;
  double horizon = 0.0;  // whole frames of the slowest rate within the problem's horizon
  std::vector<frame_rate_run> runs;
};

// The results of the study's parts besides the sweep's rows: one value a part, of the
// part's own type, which is its key (a part's file declares it; parts/part.hpp). A part
// that did not run has none; get() then gives an empty value.
class part_results {
 public:
  template <class T>
  const T* find() const {
    const auto it = items_.find(std::type_index(typeid(T)));
    return it == items_.end() ? nullptr : static_cast<const T*>(it->second.get());
  }
  template <class T>
  T* find() {
    const auto it = items_.find(std::type_index(typeid(T)));
    return it == items_.end() ? nullptr : static_cast<T*>(it->second.get());
  }
  template <class T>
  const T& get() const {
    static const T none{};
    const T* found = find<T>();
    return found ? *found : none;
  }
  template <class T>
  T& put(T value) {
    auto item = std::make_shared<T>(std::move(value));
    T& out = *item;
    items_[std::type_index(typeid(T))] = std::move(item);
    return out;
  }

 private:
  std::map<std::type_index, std::shared_ptr<void>> items_;
};

struct study {
  sweep_options options;
  bool swept = false;  // made by run_sweep (a scan-only file is not): the file records the selection and shard
  std::vector<problem_study> problems;  // the sweep's rows, which the other parts read
  part_results results;                 // every other part's
  double wall_seconds = 0.0;
  std::optional<timing_settings> timed;
};

// Checks the options (names, ladder sizes, overrides) and throws std::invalid_argument
// with a one-line message on the first problem found; run before any work or output.
void validate(const sweep_options& opts);

// The ladder's timesteps for a horizon, to its longest (max_levels): a fixed-step
// method's rows are a prefix of it, at least `levels` long.
std::vector<double> dt_ladder(double horizon, const sweep_options& opts);
// The ladder of a method: dts or tolerances.
std::vector<double> param_ladder(const method_info& m, double horizon, const sweep_options& opts);

// The problem with its overrides applied and checked.
std::unique_ptr<problem_instance> configured_problem(const std::string& name, const sweep_options& opts);

// Runs one method over its ladder on a problem whose truth is built, measures every
// row and fits the order.
method_study run_method(const problem_study& ps, const method_info& m, const sweep_options& opts);

// Fits the observed order (or, for adaptive methods, the slope of error against the
// tolerance) from the rows, and checks it against the declared order.
void fit_rows(method_study& ms, double pos_scale);

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

#pragma once
// The study as the run fills it and the reader reads it: its options, every selected
// method's rows on every selected problem (the sweep), and each other part's results
// (parts/part.hpp). Data only: what runs, judges, stores and renders it lives in run/,
// judge/, store/ and render/.
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <typeindex>
#include <utility>
#include <vector>

#include "core/convergence_fit.hpp"
#include "core/measure.hpp"
#include "core/method.hpp"
#include "study/challenge.hpp"
#include "study/energy.hpp"
#include "study/loop.hpp"
#include "study/method_row.hpp"
#include "study/scan.hpp"
#include "study/stability.hpp"
#include "study/substeps.hpp"
#include "study/verdict.hpp"

namespace stepbench {

// 10^-first, 10^-(first + stride), ... down to 10^-last: the tolerance ladder and the
// equal-error targets are both decades, built here.
inline std::vector<double> decades(int first, int last, int stride) {
  std::vector<double> out;
  for (int e = first; e <= last; e += stride) out.push_back(std::pow(10.0, -e));
  return out;
}
// Relative tolerances of the adaptive methods: 1e-2 .. 1e-14, down to round-off, so that
// every equal-error target (1e-2 .. 1e-12) is reachable (every other one when
// `thinned`).
inline std::vector<double> tolerance_ladder(bool thinned = false) { return decades(2, 14, thinned ? 2 : 1); }
// The error targets of the equal-error table written with every problem and of the
// verdict: 1e-2 .. 1e-12.
inline std::vector<double> equal_error_targets() { return decades(2, 12, 1); }
inline std::vector<double> verdict_targets() { return equal_error_targets(); }

struct substep_options {
  std::vector<std::string> problems{"stiff_spring", "spring_chain", "n_pendulum"};
  // xpbd's n substeps of one constraint pass: the method the Small Steps paper is about.
  std::vector<std::string> explicit_methods{"semi_implicit_euler", "velocity_verlet", "xpbd"};
  std::vector<std::string> implicit_methods{"implicit_euler", "implicit_midpoint"};
  std::vector<int> counts{1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
  int frames = 32;  // the frame is horizon / frames; the truth's sample times are its ends
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
  run_limits limits{};               // the work budget of one run (core/method.hpp)
  substep_options substeps{};        // the small-steps comparison (study/substeps.hpp)
  loop_options loop{};               // the game-loop study (study/loop.hpp)
  energy_options energy{};           // the long-run energy study (study/energy.hpp)
  frame_rate_options frame_rates{};  // the game programmer's frame-rate table (study/verdict.hpp)
  // Parameter scans (study/scan.hpp), under /scan; unset: the default scans
  // (run/scan.hpp default_scans).
  std::optional<std::vector<scan_options>> scans;
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

struct method_study {
  method_info info;  // as read from a file: name, description, origin, kind, declared order, traits, library
  std::vector<method_row> rows;
  fit_result fit;                 // against dt (fixed-step) or against the tolerance (adaptive)
  int declared_order_holds = -1;  // see core/convergence_fit.hpp
  std::string ladder_end;         // why the ladder stopped after its last row
};

// A problem's sweep. The judges read its facts (name, unit, parameters, truth, rows),
// which the run and the reader (store/study_reader.hpp) both fill; the live problem is
// the run's alone (null in a study read from a file).
struct problem_study {
  std::string name, unit;                // the problem's name and position unit
  std::map<std::string, double> params;  // its declared parameters' values, by name
  std::unique_ptr<problem_instance> problem;
  double horizon = 0.0;
  int dim = 0;  // coordinates of its position (as read from a file; the problem's own in a run)
  // As read from a file: source, trusted, note, the references' outcomes (not their
  // solutions) and the scales; not the truth's states.
  truth_table truth;
  std::vector<method_study> methods;
  const method_study* find(std::string_view method) const {
    for (const auto& m : methods)
      if (m.info.name == method) return &m;
    return nullptr;
  }
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
    return const_cast<T*>(std::as_const(*this).find<T>());
  }
  template <class T>
  const T& get() const {
    static const T none{};
    const T* found = find<T>();
    return found ? *found : none;
  }
  template <class T>
  T& put(T value) {
    auto& item = items_[std::type_index(typeid(T))] = std::make_shared<T>(std::move(value));
    return *static_cast<T*>(item.get());
  }

 private:
  std::map<std::type_index, std::shared_ptr<void>> items_;
};

// What a study file records besides its parts, as the reader reads it back: its path,
// format, and root attributes (build, machine, settings), strings and numbers apart.
struct study_record {
  std::string path;
  long format_version = 0;
  std::map<std::string, std::string> meta;
  std::map<std::string, double> settings;
};

struct study {
  sweep_options options;  // the run's; as read from a file, the defaults (the file's are in `record`)
  bool swept = false;     // made by run_sweep (a scan-only file is not): the file records the selection and shard
  std::vector<problem_study> problems;  // the sweep's rows, which the other parts read
  part_results results;                 // every other part's
  double wall_seconds = 0.0;
  std::optional<timing_settings> timed;  // as read from a file: present (default settings) when timed
  std::optional<study_record> record;    // a study read from a file
  const problem_study* find(std::string_view problem) const {
    for (const auto& ps : problems)
      if (ps.name == problem) return &ps;
    return nullptr;
  }
};

}  // namespace stepbench

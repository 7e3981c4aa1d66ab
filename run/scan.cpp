#include "run/scan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/measure.hpp"
#include "core/number.hpp"
#include "core/statistics.hpp"
#include "core/text.hpp"
#include "registry/registry.hpp"
#include "run/balanced_share.hpp"
#include "run/frame_rates.hpp"
#include "run/machine.hpp"
#include "study/verdict.hpp"

namespace stepbench {
namespace {

double number(std::string_view text, std::string_view what, std::string_view axis) {
  if (const auto v = finite_number(text)) return *v;
  throw std::invalid_argument(fmt::format("--param {}: {} '{}' is not a finite number", axis, what, text));
}

// The grid points of this run's shard (validate checked it exists), in grid order: each
// point's size is counted as its problem's coordinates (the force work of a step grows
// with them), and the points, largest first (ties in grid order), go each to the shard
// with the least so far (ties to the lowest shard). Deterministic: every machine computes
// the same split.
std::vector<std::size_t> scan_shard(const scan_options& opts) {
  const int k = opts.shard_index, n = opts.shard_count;
  const auto grid = scan_grid(opts.axes);
  std::vector<std::size_t> all(grid.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  if (n == 1) return all;
  // A point's size: its runs' coordinate-steps (each rate's frames x the substeps), plus
  // its references' predicted work where they run (in coordinate evaluations: at large N
  // the references are most of a point's time). The same for every method, so not counted.
  double substeps = 0.0, rates = 0.0;
  for (int n : opts.substeps) substeps += n;
  for (double hz : opts.hz) rates += hz;
  std::vector<double> size(grid.size(), 1.0);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    auto p = make_problem(opts.problem);
    for (const auto& [name, value] : opts.fixed) p->set(name, value);
    for (std::size_t a = 0; a < opts.axes.size(); ++a) p->set(opts.axes[a].param, grid[i][a]);
    if (!p->validate().empty()) continue;
    const double horizon = frames_of(p->horizon(), opts.hz).horizon;
    size[i] = static_cast<double>(p->dim()) * horizon * rates * substeps;
    if (!p->has_closed_form())
      if (const double refs = predicted_reference_work(*p, horizon); refs <= opts.reference_budget)
        size[i] += reference_work_in_evaluations * refs;
  }
  return balanced_share(size, k, n);
}

}  // namespace

scan_axis parse_scan_axis(std::string_view text, const std::string& problem) {
  const auto eq = text.find('=');
  const auto dot = text.find('.');
  if (eq == std::string_view::npos || dot == std::string_view::npos || dot > eq)
    throw std::invalid_argument(fmt::format("malformed --param '{}': expected problem.name=lo:hi:count[:log]", text));
  const std::string_view target = text.substr(0, dot), name = text.substr(dot + 1, eq - dot - 1);
  if (target != problem)
    throw std::invalid_argument(fmt::format("--param {}: the scan is of {}, not {}", text, problem, target));
  const auto parts = split(text.substr(eq + 1), ':');
  if (parts.size() < 3 || parts.size() > 4 || (parts.size() == 4 && parts[3] != "log"))
    throw std::invalid_argument(fmt::format("malformed --param '{}': expected problem.name=lo:hi:count[:log]", text));
  scan_axis a;
  a.param = std::string(name);
  a.lo = number(parts[0], "lo", text);
  a.hi = number(parts[1], "hi", text);
  const double count = number(parts[2], "count", text);
  if (!(count >= 1 && count <= 1e5 && count == std::floor(count)))
    throw std::invalid_argument(fmt::format("--param {}: count must be a whole number from 1 to 100000", text));
  a.count = static_cast<int>(count);
  a.log = parts.size() == 4;
  if (a.count > 1 && !(a.lo < a.hi)) throw std::invalid_argument(fmt::format("--param {}: lo must be below hi", text));
  if (a.log && !(a.lo > 0.0)) throw std::invalid_argument(fmt::format("--param {}: a log axis needs lo > 0", text));
  const auto params = make_problem(problem)->params();
  const auto it = std::find_if(params.begin(), params.end(), [&](const param_value& p) { return p.name == name; });
  if (it == params.end()) {
    std::string known;
    for (const auto& p : params) known += (known.empty() ? "" : ", ") + p.name;
    throw std::invalid_argument(
        fmt::format("--param {}: {} has no parameter '{}' (it has {})", text, problem, name, known));
  }
  for (double v : {a.lo, a.hi})
    if (auto why = it->check(v); !why.empty())
      throw std::invalid_argument(fmt::format("--param {}: {} is outside the parameter's range: {}", text, v, why));
  if (it->allowed.whole) {
    if (a.lo != std::floor(a.lo) || a.hi != std::floor(a.hi))
      throw std::invalid_argument(fmt::format("--param {}: {} takes whole numbers", text, a.param));
    a.whole = true;  // the points between are rounded
    const auto v = a.values();
    for (std::size_t i = 1; i < v.size(); ++i)
      if (v[i] == v[i - 1])
        throw std::invalid_argument(fmt::format(
            "--param {}: {} takes whole numbers, and the axis repeats {:g}: use fewer points", text, a.param, v[i]));
  }
  return a;
}

std::vector<std::vector<double>> scan_grid(const std::vector<scan_axis>& axes) {
  std::vector<std::vector<double>> out{{}};
  for (const auto& axis : axes) {
    std::vector<std::vector<double>> next;
    for (const auto& prefix : out)
      for (double v : axis.values()) {
        next.push_back(prefix);
        next.back().push_back(v);
      }
    out = std::move(next);
  }
  return out;
}

void validate(const scan_options& opts) {
  auto problem = make_problem(opts.problem);  // throws, naming an unknown problem
  for (std::size_t i = 0; i < opts.axes.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (opts.axes[i].param == opts.axes[j].param)
        throw std::invalid_argument(fmt::format("scan: parameter {} is given two axes", opts.axes[i].param));
  double points = 1.0;
  for (const auto& a : opts.axes) points *= a.count;
  if (points > 1e6) throw std::invalid_argument(fmt::format("scan: {:.3g} grid points; the limit is 10^6", points));
  if (opts.hz.empty()) throw std::invalid_argument("scan: no frame rate");
  const double fastest = *std::max_element(opts.hz.begin(), opts.hz.end());
  for (double hz : opts.hz)
    if (!(hz > 0.0 && std::isfinite(hz)) || std::abs(fastest / hz - std::round(fastest / hz)) > 1e-9)
      throw std::invalid_argument(
          fmt::format("scan: frame rate {:g} Hz does not divide the fastest, {:g} Hz", hz, fastest));
  if (opts.substeps.empty()) throw std::invalid_argument("scan: no substep count");
  // A rate or substep count given twice would count its runs twice over the range.
  for (std::size_t i = 0; i < opts.hz.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (opts.hz[i] == opts.hz[j])
        throw std::invalid_argument(fmt::format("scan: frame rate {:g} Hz is given twice", opts.hz[i]));
  for (std::size_t i = 0; i < opts.substeps.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (opts.substeps[i] == opts.substeps[j])
        throw std::invalid_argument(fmt::format("scan: substeps {} is given twice", opts.substeps[i]));
  for (int n : opts.substeps)
    if (n < 1 || n > 1 << 20) throw std::invalid_argument(fmt::format("scan: substeps {} is not in 1 .. 2^20", n));
  if (opts.shard_count < 1 || opts.shard_index < 0 || opts.shard_index >= opts.shard_count)
    throw std::invalid_argument(
        fmt::format("scan: shard {} of {} does not exist", opts.shard_index + 1, opts.shard_count));
  if (!(opts.tol > 0.0 && std::isfinite(opts.tol)))
    throw std::invalid_argument("scan: the tolerance must be a positive number");
  const auto methods = problem->methods();
  for (const auto& m : opts.methods) {
    const auto it = std::find_if(methods.begin(), methods.end(), [&](const method_info& i) { return i.name == m; });
    if (it == methods.end()) throw std::invalid_argument(fmt::format("scan: {} does not run on {}", m, opts.problem));
    if (it->kind != method_kind::fixed_step)
      throw std::invalid_argument(fmt::format("scan: {} is adaptive; a scan runs fixed-step methods", m));
  }
  for (const auto& [name, value] : opts.fixed) {
    problem->set(name, value);  // throws for an unknown parameter
    for (const auto& a : opts.axes)
      if (a.param == name) throw std::invalid_argument(fmt::format("scan: {} is both set and scanned", name));
  }
  // The frame ends' bound (run/frame_rates.hpp) at the problem as set: refused here, not
  // after minutes of points; a grid point over it (a horizon or a size scanned) is recorded
  // as not run, with the reason.
  if (problem->validate().empty())
    if (const auto why = frames_over_limit(problem->horizon(), opts.hz, problem->dim()); !why.empty())
      throw std::invalid_argument(fmt::format("scan: {}: give a lower --hz or a shorter horizon", why));
}

std::vector<scan_options> default_scans(bool quick) {
  scan_options spring;
  spring.problem = "stiff_spring";
  spring.axes = {
      parse_scan_axis(quick ? "stiff_spring.k_s=1e1:1e7:13:log" : "stiff_spring.k_s=1e1:1e7:25:log", "stiff_spring")};
  if (quick) {
    spring.hz = {60};
    spring.substeps = {1, 4, 16};
    return {spring};
  }
  scan_options pendulum;
  pendulum.problem = "pendulum";
  pendulum.axes = {parse_scan_axis("pendulum.theta0_deg=1:179.9:12", "pendulum")};
  // The rope has no closed form: each point's truth is the references' (GSL rk8pd, CVODE
  // ...), whose work grows as coordinates x w_max T, about masses^1.5 k_s^0.5. Within the
  // reference budget (scan_options::reference_budget) are 8 and 64 masses at every k_s and
  // 512 at the softest; the rest of the range to 4096 masses is judged on stability. The
  // runs' work budget is a quarter of the default (2^23 coordinate force evaluations, about
  // 2.5e-2 s of force work a run): at 4096 masses a run of more than 680 evaluations is
  // skipped, which keeps the scan at 27 s on two cores in the full study (the 60 s
  // for all three).
  scan_options chain;
  chain.problem = "spring_chain";
  chain.limits.work_budget = 1 << 23;
  chain.axes = {parse_scan_axis("spring_chain.masses=8:4096:4:log", "spring_chain"),
                parse_scan_axis("spring_chain.k_s=1e2:1e5:4:log", "spring_chain")};
  return {spring, pendulum, chain};
}

namespace {
// The methods a scan runs: the named ones, or our fixed-step methods on the problem.
std::vector<method_info> scan_methods(const problem_instance& problem, const scan_options& opts) {
  std::vector<method_info> out;
  for (const auto& m : problem.methods())
    if (m.kind == method_kind::fixed_step &&
        (opts.methods.empty() ? offered_as_ours(m.origin)
                              : std::find(opts.methods.begin(), opts.methods.end(), m.name) != opts.methods.end()))
      out.push_back(m);
  return out;
}
}  // namespace

scan_result run_scan(const scan_options& opts) {
  validate(opts);
  const auto start = std::chrono::steady_clock::now();
  scan_result out;
  out.options = opts;
  auto proto = make_problem(opts.problem);
  out.unit = std::string(proto->position_unit());
  const std::vector<method_info> methods = scan_methods(*proto, opts);
  out.options.methods.clear();  // the file records the methods run, which merge compares
  for (const auto& m : methods) out.options.methods.push_back(m.name);
  const auto grid = scan_grid(opts.axes);
  const auto mine = scan_shard(opts);
  out.grid_points = grid.size();
  const double fastest = *std::max_element(opts.hz.begin(), opts.hz.end());

  // Each point on its own: its problem, truth and runs, into its slot (the result does
  // not depend on the threads), then concatenated in grid order.
  struct point_work {
    scan_point point;
    std::vector<scan_run> runs;
  };
  std::vector<point_work> work(mine.size());
  const auto run_point = [&](std::size_t local) {
    const std::size_t i = mine[local];
    auto& w = work[local];
    w.point.index = i;
    w.point.values = grid[i];
    auto problem = make_problem(opts.problem);
    for (const auto& [name, value] : opts.fixed) problem->set(name, value);
    for (std::size_t a = 0; a < opts.axes.size(); ++a) problem->set(opts.axes[a].param, grid[i][a]);
    if (auto why = problem->validate(); !why.empty()) {
      w.point.trusted = false;
      w.point.truth_source = "none";
      w.point.note = "not run: " + why;
      return;
    }
    if (auto why = frames_over_limit(problem->horizon(), opts.hz, problem->dim()); !why.empty()) {
      w.point.trusted = false;
      w.point.truth_source = "none";
      w.point.note = "not run: " + why;
      return;
    }
    const frames f = frames_of(problem->horizon(), opts.hz);
    w.point.horizon = f.horizon;
    // A closed form is the truth; the references are run only without one (checking
    // them against it at every grid point would be most of a scan's time).
    const truth_table fine = build_truth(*problem, f.times,
                                         {.run_references = !problem->has_closed_form(),
                                          .tol = opts.ref_tol,
                                          .reference_budget = opts.reference_budget});
    w.point.truth_source = fine.source;
    w.point.trusted = fine.trusted;
    w.point.note = fine.note;
    w.point.pos_scale = fine.pos_scale;
    // A fixed-step run ignores the work budget, so each run's work is estimated before it
    // is taken, as the sweep's ladder does (study/sweep.cpp): steps x force evaluations a
    // step x coordinates, the evaluations a step as this method took them at this point
    // in its last run, else as it declares them, else one (the least a step takes). A run
    // over the budget is recorded as skipped, with the estimate.
    const double dim = problem->dim();
    std::vector<double> evals_per_step;
    for (const auto& m : methods) evals_per_step.push_back(std::isfinite(m.evals_per_step) ? m.evals_per_step : 1.0);
    for (double hz : opts.hz) {
      const truth_table truth = every_nth(fine, static_cast<std::size_t>(std::lround(fastest / hz)));
      for (std::size_t k = 0; k < methods.size(); ++k)
        for (int n : opts.substeps) {
          const std::string& name = methods[k].name;
          const double dt = 1.0 / (hz * n);
          const double steps = f.horizon / dt, work = steps * evals_per_step[k] * dim;
          if (work > opts.limits.work_budget) {
            w.runs.push_back({local, hz, name, n,
                              skipped_row(dt, fmt::format("skipped: about {:.3g} steps x {:g} force evaluations x {:g} "
                                                          "coordinates exceed the work budget of {:.3g}",
                                                          steps, evals_per_step[k], dim, opts.limits.work_budget))});
            continue;
          }
          const run_result run = problem->run(name, dt, f.horizon, truth.times, opts.limits);
          if (run.steps > 0 && run.work.force_evals > 0)
            evals_per_step[k] = static_cast<double>(run.work.force_evals) / static_cast<double>(run.steps);
          run_metrics m = measure(*problem, run, truth);
          if (!truth.trusted && !m.diverged && !run.skipped && !run.non_finite && run.stop_reason.empty()) {
            // Nothing to measure its error against, but the run completed: stable here.
            m.failed = false;
            m.note = "completed; no trusted truth at this point to measure its error";
          }
          w.runs.push_back({local, hz, name, n, {dt, run.steps, run.rejected_steps, run.work, std::move(m), {}}});
        }
    }
  };
  std::size_t done = 0;
  parallel_indices(mine.size(), opts.jobs, run_point, [&] {
    ++done;
    if (opts.on_progress) opts.on_progress(done, mine.size());
  });

  for (auto& w : work) {
    out.points.push_back(std::move(w.point));
    for (auto& r : w.runs) out.runs.push_back(std::move(r));
  }
  compute_best(out);
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::map<std::string, double> eval_costs_timed_here(const scan_options& opts) {
  validate(opts);
  auto problem = make_problem(opts.problem);
  for (const auto& [name, value] : opts.fixed) problem->set(name, value);
  if (auto why = problem->validate(); !why.empty()) throw std::invalid_argument(why);
  const double hz = *std::max_element(opts.hz.begin(), opts.hz.end());
  const double dt = 1.0 / (hz * *std::max_element(opts.substeps.begin(), opts.substeps.end()));
  constexpr double frames_timed = 8;
  const double horizon = std::min(problem->horizon(), frames_timed / hz);
  const std::vector<double> times{horizon};
  std::map<std::string, double> out;
  for (const auto& m : scan_methods(*problem, opts)) {
    const double evals = static_cast<double>(problem->run(m.name, dt, horizon, times, opts.limits).work.force_evals);
    if (!(evals > 0)) continue;
    const auto run = problem->timed_run(m.name, dt, horizon, times, opts.limits);
    volatile double keep = run();  // warm: the first call pays for the caches and the page faults
    std::vector<double> per_eval;
    for (int batch = 0; batch < 5; ++batch) {
      long calls = 0;
      const auto start = std::chrono::steady_clock::now();
      double ns = 0.0;
      do {
        keep = run();
        ++calls;
        ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
      } while (ns < 1e7);
      per_eval.push_back(ns / static_cast<double>(calls) / evals);
    }
    (void)keep;
    out[m.name] = median(per_eval);
  }
  return out;
}

}  // namespace stepbench

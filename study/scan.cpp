#include "study/scan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "core/measure.hpp"
#include "registry/registry.hpp"
#include "study/balanced_share.hpp"
#include "study/h5.hpp"
#include "study/machine.hpp"
#include "study/verdict.hpp"

namespace stepbench {
namespace {

double number(std::string_view text, std::string_view what, std::string_view axis) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    throw std::invalid_argument(fmt::format("--param {}: {} '{}' is not a finite number", axis, what, text));
  return v;
}

std::vector<std::string_view> split(std::string_view text, char sep) {
  std::vector<std::string_view> out;
  for (std::size_t start = 0;;) {
    const auto at = text.find(sep, start);
    out.push_back(text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
    if (at == std::string_view::npos) return out;
    start = at + 1;
  }
}

// The frame-rate study's frames: whole frames of the slowest rate within the problem's
// horizon, the truth at the fastest rate's frame ends (every rate divides the fastest).
struct frames {
  double horizon = 0.0;
  std::vector<double> times;
};

frames frames_of(double problem_horizon, const std::vector<double>& hz) {
  const double slowest = *std::min_element(hz.begin(), hz.end());
  const double fastest = *std::max_element(hz.begin(), hz.end());
  frames f;
  const long slow_frames = std::max(1L, static_cast<long>(std::floor(problem_horizon * slowest * (1.0 + 1e-12))));
  f.horizon = static_cast<double>(slow_frames) / slowest;
  const long fast_frames = std::lround(f.horizon * fastest);
  for (long j = 1; j <= fast_frames; ++j) f.times.push_back(static_cast<double>(j) / fastest);
  return f;
}

}  // namespace

std::vector<double> scan_axis::values() const {
  // Log axes in powers of ten, so that whole decades are exact (glibc's pow is exact
  // for 10^k); both ends are the values given.
  std::vector<double> out;
  for (int i = 0; i < count; ++i) {
    const double s = count == 1 ? 0.0 : static_cast<double>(i) / (count - 1);
    out.push_back(i == 0           ? lo
                  : i == count - 1 ? hi
                  : log            ? std::pow(10.0, std::log10(lo) + s * (std::log10(hi) - std::log10(lo)))
                                   : lo + s * (hi - lo));
    if (whole) out.back() = std::round(out.back());
  }
  return out;
}

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
  if (opts.axes.empty()) throw std::invalid_argument("scan: give at least one --param axis");
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
}

namespace {

// The cheapest run meeting the tolerance at each point and rate: fewest force
// evaluations (the same frames at one rate, so the total compares), then fewer substeps.
void compute_best(scan_result& s) {
  const auto& hz = s.options.hz;
  std::vector<const scan_run*> pick(s.points.size() * hz.size(), nullptr);
  for (const auto& r : s.runs) {
    const auto rate = static_cast<std::size_t>(std::find(hz.begin(), hz.end(), r.hz) - hz.begin());
    if (rate == hz.size() || !r.row.metrics.completed() || !(r.row.metrics.err_pos_max <= s.options.tol)) continue;
    const scan_run*& p = pick[r.point * hz.size() + rate];
    if (!p || r.row.work.force_evals < p->row.work.force_evals ||
        (r.row.work.force_evals == p->row.work.force_evals && r.substeps < p->substeps))
      p = &r;
  }
  s.best.clear();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < s.points.size(); ++i)
    for (std::size_t k = 0; k < hz.size(); ++k) {
      scan_best b{i, hz[k], "", 0, nan, nan};
      if (const scan_run* p = pick[i * hz.size() + k]) {
        b.method = p->method;
        b.substeps = p->substeps;
        b.err_pos_max = p->row.metrics.err_pos_max;
        b.force_evals_per_frame = static_cast<double>(p->row.work.force_evals) / (s.points[i].horizon * hz[k]);
      }
      s.best.push_back(b);
    }
}

}  // namespace

std::vector<std::size_t> scan_shard(const scan_options& opts, int k, int n) {
  if (n < 1 || k < 0 || k >= n) throw std::invalid_argument(fmt::format("shard {} of {} does not exist", k + 1, n));
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

scan_result merge_scans(const std::vector<scan_result>& shards, bool partial, std::vector<std::size_t>& missing) {
  if (shards.empty()) throw std::invalid_argument("merge: no shard");
  const auto& first = shards.front();
  // What makes two shards one scan, each as text: doubles in fmt's shortest form that
  // reads back exactly, so equal text is equal values, and the refusal can show both.
  const auto described = [](const scan_result& s) {
    const auto& o = s.options;
    std::vector<std::string> axes, fixed;
    for (const auto& a : o.axes)
      axes.push_back(fmt::format("{}={}:{}:{}{}", a.param, a.lo, a.hi, a.count, a.log ? ":log" : ""));
    for (const auto& [name, value] : o.fixed) fixed.push_back(fmt::format("{}={}", name, value));
    return std::vector<std::pair<std::string_view, std::string>>{
        {"problem", o.problem},
        {"axes", fmt::format("{}", fmt::join(axes, " x "))},
        {"frame rates", fmt::format("{} Hz", fmt::join(o.hz, ","))},
        {"substeps", fmt::format("{}", fmt::join(o.substeps, ","))},
        {"methods", fmt::format("{}", fmt::join(o.methods, ","))},
        {"tolerance", fmt::format("{}", o.tol)},
        {"fixed parameters (--set)", fixed.empty() ? "none" : fmt::format("{}", fmt::join(fixed, ","))},
        {"reference tolerances", fmt::format("rtol {} atol {}", o.ref_tol.rtol, o.ref_tol.atol)},
        {"reference budget", fmt::format("{}", o.reference_budget)},
        {"work budget", fmt::format("{}", o.limits.work_budget)},
        {"grid", fmt::format("{} points", s.grid_points)}};
  };
  const auto label = [](const scan_result& s, std::size_t k) {
    return s.source.empty() ? fmt::format("shard {}", k + 1) : fmt::format("'{}'", s.source);
  };
  const auto want = described(first);
  for (std::size_t k = 1; k < shards.size(); ++k) {
    const auto have = described(shards[k]);
    for (std::size_t i = 0; i < want.size(); ++i)
      if (have[i].second != want[i].second)
        throw std::invalid_argument(fmt::format("merge: scan '{}': the shards differ in their {}: {} has {}, {} has {}",
                                                first.options.name, want[i].first, label(first, 0), want[i].second,
                                                label(shards[k], k), have[i].second));
  }
  // Every point once: the first shard holding it, refusing a second.
  std::vector<std::pair<const scan_result*, std::size_t>> owner(first.grid_points, {nullptr, 0});
  for (const auto& s : shards)
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const std::size_t g = s.points[i].index;
      if (g >= owner.size())
        throw std::invalid_argument(
            fmt::format("merge: scan '{}' has point {} beyond its grid of {}", first.options.name, g, owner.size()));
      if (owner[g].first)
        throw std::invalid_argument(fmt::format("merge: scan '{}': grid point {} is in two shards (overlapping shards)",
                                                first.options.name, g));
      owner[g] = {&s, i};
    }
  missing.clear();
  for (std::size_t g = 0; g < owner.size(); ++g)
    if (!owner[g].first) missing.push_back(g);
  if (!missing.empty() && !partial)
    throw std::invalid_argument(
        fmt::format("merge: scan '{}': {} of {} grid points are in no shard (first: {}); "
                    "--partial merges what there is",
                    first.options.name, missing.size(), owner.size(), missing.front()));
  // Each shard's runs by its local point, to carry them over in grid order.
  scan_result out;
  out.options = first.options;
  out.options.shard_index = 0;
  out.options.shard_count = 1;
  out.unit = first.unit;
  out.grid_points = first.grid_points;
  std::map<const scan_result*, std::vector<std::vector<const scan_run*>>> runs_of;
  for (const auto& s : shards) {
    auto& by_point = runs_of[&s];
    by_point.resize(s.points.size());
    for (const auto& r : s.runs) by_point.at(r.point).push_back(&r);
  }
  for (std::size_t g = 0; g < owner.size(); ++g) {
    const auto [s, i] = owner[g];
    if (!s) continue;
    const std::size_t local = out.points.size();
    out.points.push_back(s->points[i]);
    for (const scan_run* r : runs_of[s][i]) {
      out.runs.push_back(*r);
      out.runs.back().point = local;
    }
  }
  for (const auto& s : shards) out.wall_seconds += s.wall_seconds;
  compute_best(out);
  return out;
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

scan_result run_scan(const scan_options& opts) {
  validate(opts);
  const auto start = std::chrono::steady_clock::now();
  scan_result out;
  out.options = opts;
  auto proto = make_problem(opts.problem);
  out.unit = std::string(proto->position_unit());
  std::vector<method_info> methods;
  for (const auto& m : proto->methods())
    if (m.kind == method_kind::fixed_step &&
        (opts.methods.empty() ? m.origin == method_origin::ours
                              : std::find(opts.methods.begin(), opts.methods.end(), m.name) != opts.methods.end()))
      methods.push_back(m);
  out.options.methods.clear();  // the file records the methods run, which merge compares
  for (const auto& m : methods) out.options.methods.push_back(m.name);
  const auto grid = scan_grid(opts.axes);
  const auto mine = scan_shard(opts, opts.shard_index, opts.shard_count);
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

}  // namespace stepbench

namespace stepbench {
namespace {

std::string param_unit(const std::string& problem, const std::string& param) {
  try {
    for (const auto& p : make_problem(problem)->params())
      if (p.name == param) return p.unit == "1" ? "" : " " + p.unit;
  } catch (const std::exception&) {
  }
  return "";
}

std::string range_text(const scan_result& s) {
  std::vector<std::string> parts;
  for (const auto& a : s.options.axes)
    parts.push_back(fmt::format("{} {:g} .. {:g}{} ({} points{})", a.param, a.lo, a.hi,
                                param_unit(s.options.problem, a.param), a.count, a.log ? ", log" : ""));
  return fmt::format("{}", fmt::join(parts, " x "));
}

}  // namespace

scan_answer answer_scan(const scan_result& s, double tol) {
  scan_answer a;
  a.problem = s.options.problem;
  a.unit = s.unit;
  a.tol = tol;
  a.range = range_text(s);
  a.points = s.points.size();
  a.grid_points = s.grid_points;
  for (const auto& p : s.points) a.untrusted += p.trusted ? 0 : 1;
  // Runs by (rate, method, substeps): stability over every point (a run diverged or not
  // whatever the truth), error and cost over the points with a trusted truth.
  struct combo {
    double hz;
    std::string method;
    int substeps;
    std::size_t runs = 0, judged = 0, within = 0, skipped = 0;
    double worst = 0.0, cost = 0.0;
    std::vector<std::size_t> unstable;  // point indices
  };
  std::vector<combo> combos;
  const auto find_combo = [&](double hz, const std::string& m, int n) -> combo& {
    for (auto& c : combos)
      if (c.hz == hz && c.method == m && c.substeps == n) return c;
    combos.push_back({hz, m, n, 0, 0, 0, 0, 0.0, 0.0, {}});
    return combos.back();
  };
  for (const auto& r : s.runs) {
    const auto& p = s.points[r.point];
    combo& c = find_combo(r.hz, r.method, r.substeps);
    ++c.runs;
    const auto& m = r.row.metrics;
    if (m.diverged || m.failed) c.unstable.push_back(r.point);
    if (m.skipped) ++c.skipped;
    if (!p.trusted) continue;
    ++c.judged;
    if (m.completed() && m.err_pos_max <= tol) ++c.within;
    c.worst = m.completed() ? std::max(c.worst, m.err_pos_max) : std::numeric_limits<double>::infinity();
    c.cost = std::max(c.cost, static_cast<double>(r.row.work.force_evals) / (p.horizon * r.hz));
  }
  const std::size_t trusted = a.points - a.untrusted;
  for (double hz : s.options.hz) {
    scan_choice best{hz, "", 0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    for (const auto& c : combos) {
      // Within the tolerance at every point with a truth, and stable at every point.
      if (c.hz != hz || c.judged != trusted || c.within != trusted || trusted == 0 || c.runs != a.points ||
          !c.unstable.empty() || c.skipped > 0)
        continue;
      if (best.method.empty() || c.cost < best.max_force_evals_per_frame ||
          (c.cost == best.max_force_evals_per_frame && c.substeps < best.substeps))
        best = {hz, c.method, c.substeps, c.worst, c.cost};
    }
    a.choices.push_back(best);
    for (const auto& c : combos) {
      if (c.hz != hz || c.substeps != 1) continue;
      scan_break b{hz, c.method, c.unstable.size(), c.runs, ""};
      if (!c.unstable.empty() && s.options.axes.size() == 1) {
        // One axis: the unstable values as ranges of consecutive grid points.
        const auto& axis = s.options.axes[0];
        const std::string unit = param_unit(s.options.problem, axis.param);
        std::vector<std::string> spans;
        for (std::size_t k = 0; k < c.unstable.size();) {
          std::size_t e = k;
          // Consecutive in the grid (a merged --partial scan may lack points between).
          while (e + 1 < c.unstable.size() && s.points[c.unstable[e + 1]].index == s.points[c.unstable[e]].index + 1)
            ++e;
          const double lo = s.points[c.unstable[k]].values[0], hi = s.points[c.unstable[e]].values[0];
          const bool to_end = s.points[c.unstable[e]].index + 1 == s.grid_points,
                     from_start = s.points[c.unstable[k]].index == 0;
          spans.push_back(to_end && !from_start   ? fmt::format("{} >= {:.3g}{}", axis.param, lo, unit)
                          : from_start && !to_end ? fmt::format("{} <= {:.3g}{}", axis.param, hi, unit)
                          : lo == hi              ? fmt::format("{} = {:.3g}{}", axis.param, lo, unit)
                                                  : fmt::format("{} {:.3g} .. {:.3g}{}", axis.param, lo, hi, unit));
          k = e + 1;
        }
        b.where = fmt::format("diverges for {}", fmt::join(spans, ", "));
      } else if (!c.unstable.empty()) {
        std::vector<std::string> at;
        for (std::size_t k = 0; k < s.options.axes.size(); ++k)
          at.push_back(fmt::format("{} = {:.3g}", s.options.axes[k].param, s.points[c.unstable.front()].values[k]));
        b.where =
            fmt::format("diverges at {} of {} points, first at {}", c.unstable.size(), c.runs, fmt::join(at, ", "));
      } else if (c.skipped == c.runs) {
        b.where = "not run: over the work budget at every point";
      } else if (c.skipped > 0) {
        b.where = fmt::format("stable at the {} of {} points it ran (the rest over the work budget)",
                              c.runs - c.skipped, c.runs);
      } else {
        b.where = "stable everywhere";
      }
      a.breaks.push_back(b);
    }
  }
  return a;
}

std::string format_scan_answer(const scan_answer& a) {
  std::string out = fmt::format(
      "{} over {}, within {:g} {} (err_pos_max){}:\n", a.problem, a.range, a.tol, a.unit,
      a.points < a.grid_points
          ? fmt::format(", on {} of the grid's {} points (a shard, or a partial merge)", a.points, a.grid_points)
          : "");
  for (const auto& c : a.choices) {
    if (c.method.empty())
      out += fmt::format("  {:g} Hz: no method of the scan stays within {:g} {} over the whole range\n", c.hz, a.tol,
                         a.unit);
    else
      out += fmt::format(
          "  {:g} Hz: {} with {} stays stable and within {:g} {} {} (worst {:.3g} {}, "
          "{:.4g} force evaluations a frame at most)\n",
          c.hz, c.method, c.substeps == 1 ? std::string("one step a frame") : fmt::format("{} substeps", c.substeps),
          a.tol, a.unit,
          a.untrusted == 0
              ? std::string("everywhere")
              : fmt::format("at the {} points with a truth (stable at all {})", a.points - a.untrusted, a.points),
          c.worst_err, a.unit, c.max_force_evals_per_frame);
  }
  out += "At one step a frame:\n";
  for (const auto& b : a.breaks) out += fmt::format("  {:g} Hz  {:<22} {}\n", b.hz, b.method, b.where);
  if (a.untrusted > 0)
    out += fmt::format(
        "{} of {} points have no trusted truth: their runs are judged on stability alone, the tolerance on the other "
        "{} (see the scan's points table)\n",
        a.untrusted, a.points, a.points - a.untrusted);
  return out;
}

namespace {

// The names of a comma-separated attribute ("" : none; the names hold no commas).
std::vector<std::string> names_of(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  for (std::size_t start = 0; start <= text.size();) {
    const auto comma = std::min(text.find(',', start), text.size());
    out.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

}  // namespace

scan_result read_scan(const std::string& path, const std::string& name) {
  H5::Exception::dontPrint();  // errors become one line, not HDF5's stack
  scan_result s;
  try {
    if (!std::filesystem::exists(path)) throw std::runtime_error("no such file");
    if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
    const H5::H5File file(path, H5F_ACC_RDONLY);
    if (!h5::is_group(file, "scan")) throw std::runtime_error("it holds no scan (/scan is absent)");
    const H5::Group all = file.openGroup("scan");
    const auto names = h5::children(all);
    std::string which = name;
    if (which.empty()) {
      if (names.size() != 1)
        throw std::invalid_argument(
            fmt::format("'{}' holds {} scans; name one with --name ({})", path, names.size(), fmt::join(names, ", ")));
      which = names.front();
    }
    if (!h5::is_group(all, which))
      throw std::invalid_argument(
          fmt::format("'{}' has no scan '{}' (it has: {})", path, which, fmt::join(names, ", ")));
    const H5::Group g = all.openGroup(which);
    auto& o = s.options;
    o.name = which;
    o.problem = h5::string_attr(g, "problem");
    s.unit = h5::string_attr(g, "unit");
    o.tol = h5::double_attr(g, "tol");
    const auto lo = h5::double_array_attr(g, "axis_lo"), hi = h5::double_array_attr(g, "axis_hi");
    const auto count = h5::int_array_attr(g, "axis_count"), log = h5::int_array_attr(g, "axis_log");
    const std::vector<std::string> axis_names = names_of(h5::string_attr(g, "axes"));
    if (axis_names.size() != lo.size() || lo.size() != hi.size() || hi.size() != count.size() ||
        count.size() != log.size())
      throw std::runtime_error(fmt::format("scan '{}': its axis attributes differ in length", which));
    for (std::size_t k = 0; k < axis_names.size(); ++k)
      o.axes.push_back({axis_names[k], lo[k], hi[k], static_cast<int>(count[k]), log[k] != 0, false});
    o.hz = h5::double_array_attr(g, "hz");
    o.substeps.clear();  // the file's counts replace the defaults, not extend them
    for (long n : h5::int_array_attr(g, "substeps")) o.substeps.push_back(static_cast<int>(n));
    o.methods = names_of(h5::string_attr(g, "methods"));
    const auto fixed_names = names_of(h5::string_attr(g, "fixed_params"));
    const auto fixed_values = h5::double_array_attr(g, "fixed_values");
    if (fixed_names.size() != fixed_values.size())
      throw std::runtime_error(fmt::format("scan '{}': {} fixed_params but {} fixed_values", which, fixed_names.size(),
                                           fixed_values.size()));
    for (std::size_t k = 0; k < fixed_names.size(); ++k) o.fixed[fixed_names[k]] = fixed_values[k];
    o.ref_tol.rtol = h5::double_attr(g, "reference_rtol");
    o.ref_tol.atol = h5::double_attr(g, "reference_atol");
    o.limits.work_budget = h5::double_attr(g, "work_budget");
    o.reference_budget = h5::double_attr(g, "reference_budget");
    s.wall_seconds = h5::double_attr(g, "wall_seconds");
    const H5::Group values = g.openGroup("values");
    std::vector<std::vector<double>> columns;
    for (const auto& a : o.axes) columns.push_back(h5::read_vector(values.openDataSet(a.param)));
    s.grid_points = static_cast<std::size_t>(h5::long_attr(g, "grid_points"));
    double product = 1.0;  // in doubles: a damaged count cannot overflow it
    for (const auto& a : o.axes) product *= a.count;
    if (static_cast<double>(s.grid_points) != product)
      throw std::runtime_error(fmt::format("scan '{}': grid_points {} is not the product of its axes' counts, {:.0f}",
                                           which, s.grid_points, product));
    o.shard_index = static_cast<int>(h5::long_attr(g, "shard_index"));
    o.shard_count = static_cast<int>(h5::long_attr(g, "shard_count"));
    const h5::table_data points = h5::read_table(g.openDataSet("points"));
    const auto& index = points.ints("point");
    std::map<std::int64_t, std::size_t> local_of;  // grid index -> row
    const auto& trusted = points.ints("trusted");
    const auto& source = points.strings("truth_source");
    const auto& note = points.strings("note");
    const auto horizon = points.doubles("horizon"), scale = points.doubles("pos_scale");
    for (std::size_t i = 0; i < points.rows(); ++i) {
      scan_point p;
      for (const auto& c : columns) {
        if (c.size() != points.rows())
          throw std::runtime_error(fmt::format("scan '{}': values/ and points differ in length", which));
        p.values.push_back(c[i]);
      }
      if (index[i] < 0 || static_cast<std::size_t>(index[i]) >= s.grid_points || local_of.count(index[i]))
        throw std::runtime_error(
            fmt::format("scan '{}': point {} is outside its grid of {} or repeated", which, index[i], s.grid_points));
      local_of[index[i]] = i;
      p.index = static_cast<std::size_t>(index[i]);
      p.trusted = trusted[i] != 0;
      p.truth_source = source[i];
      p.note = note[i];
      p.horizon = horizon[i];
      p.pos_scale = scale[i];
      s.points.push_back(std::move(p));
    }
    const h5::table_data runs = h5::read_table(g.openDataSet("runs"));
    const auto& point = runs.ints("point");
    const auto hz = runs.doubles("hz"), dt = runs.doubles("dt"), err = runs.doubles("err_pos_max"),
               evals = runs.doubles("force_evals"), newton = runs.doubles("newton_iterations");
    const auto& method = runs.strings("method");
    const auto &substeps = runs.ints("substeps"), &steps = runs.ints("steps");
    const auto &diverged = runs.ints("diverged"), &failed = runs.ints("failed"), &skipped = runs.ints("skipped");
    const auto& run_note = runs.strings("note");
    for (std::size_t i = 0; i < runs.rows(); ++i) {
      const auto at = local_of.find(point[i]);
      if (at == local_of.end())
        throw std::runtime_error(
            fmt::format("scan '{}': run {} names point {}, which its points table lacks", which, i, point[i]));
      scan_run r;
      r.point = at->second;
      r.hz = hz[i];
      r.method = method[i];
      r.substeps = static_cast<int>(substeps[i]);
      r.row.param = dt[i];
      r.row.steps = steps[i];
      r.row.work.force_evals = static_cast<long>(evals[i]);
      r.row.work.newton_iterations = static_cast<long>(newton[i]);
      r.row.metrics.err_pos_max = err[i];
      r.row.metrics.diverged = diverged[i] != 0;
      r.row.metrics.failed = failed[i] != 0;
      r.row.metrics.skipped = skipped[i] != 0;
      r.row.metrics.note = run_note[i];
      s.runs.push_back(std::move(r));
    }
    compute_best(s);
    s.source = path;
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read the scan in '{}': {}", path, e.getDetailMsg()));
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("cannot read the scan in '{}': {}", path, e.what()));
  }
  return s;
}

std::vector<scan_result> read_scans(const std::string& path) {
  std::vector<std::string> names;
  try {
    if (!std::filesystem::exists(path)) throw std::runtime_error("no such file");
    if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
    const H5::H5File file(path, H5F_ACC_RDONLY);
    if (!h5::is_group(file, "scan")) throw std::runtime_error("it holds no scan (/scan is absent)");
    names = h5::children(file.openGroup("scan"));
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read the scans in '{}': {}", path, e.getDetailMsg()));
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("cannot read the scans in '{}': {}", path, e.what()));
  }
  std::vector<scan_result> out;
  for (const auto& name : names) out.push_back(read_scan(path, name));
  return out;
}

std::string file_build(const std::string& path) {
  H5::Exception::dontPrint();
  try {
    if (!std::filesystem::exists(path)) throw std::runtime_error("no such file");
    if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
    const H5::H5File file(path, H5F_ACC_RDONLY);
    // The compiler and the libraries too: another GSL or SUNDIALS is another truth.
    return fmt::format("format_version {}, commit {}, {} build, flags {}, {}, {}",
                       h5::long_attr(file, "format_version"), h5::string_attr(file, "git_commit"),
                       h5::string_attr(file, "build_type"), h5::string_attr(file, "build_flags"),
                       h5::string_attr(file, "compiler"), h5::string_attr(file, "dependencies"));
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read the build of '{}': {}", path, e.getDetailMsg()));
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("cannot read the build of '{}': {}", path, e.what()));
  }
}

}  // namespace stepbench

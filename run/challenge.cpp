#include "run/challenge.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "core/drive.hpp"
#include "core/measure.hpp"
#include "core/number.hpp"
#include "integrators/implicit_euler.hpp"
#include "integrators/semi_implicit_euler.hpp"
#include "integrators/xpbd.hpp"
#include "problems/n_pendulum.hpp"
#include "problems/spring_chain.hpp"
#include "registry/registry.hpp"

namespace stepbench {
namespace {

// The Small Steps designs, named after the methods they run, by the methods' own names (a
// renamed method renames its design, never drops it from the verdict).
struct small_steps_designs {
  std::string xpbd_substeps = xpbd::describe().name + "_substeps";
  std::string xpbd_passes = xpbd_iterations::describe().name;
  std::string explicit_substeps = std::string(semi_implicit_euler::name) + "_substeps";
  std::string implicit_step = std::string(implicit_euler::name);
};

// The median of `repeats` timings of a whole run, in ns (one untimed run first).
double median_ns(const std::function<void()>& run, int repeats = 5) {
  run();
  std::vector<double> t;
  for (int k = 0; k < repeats; ++k) {
    const auto start = std::chrono::steady_clock::now();
    run();
    t.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

std::vector<double> frame_ends(double hz, double horizon) {
  std::vector<double> t;
  const long frames = std::lround(horizon * hz);
  for (long i = 1; i <= frames; ++i) t.push_back(static_cast<double>(i) / hz);
  return t;
}

// One method at k steps a frame (or, adaptive, at a tolerance) over the challenge's
// horizon: error and time.
struct ladder_point {
  int k = 0;  // steps a frame; an adaptive method's: its accepted steps a frame, rounded
  double tolerance = nan;
  double err = nan, ns_per_frame = nan;
  bool completed = false;
  std::string note;
};
// An adaptive method (a finite `tol`) runs at that relative tolerance over the whole horizon
// in one run (its step size carries across frames, as a game would keep it), timed with a
// state at every frame end, which a game draws; a fixed-step one is timed to the horizon.
ladder_point measure_at(const problem_instance& p, const truth_table& truth, const std::string& method, int k,
                        double hz, double horizon, double tol = nan) {
  ladder_point out;
  out.tolerance = tol;
  const bool adaptive = std::isfinite(tol);
  const double param = adaptive ? tol : 1.0 / (hz * k);
  const run_result r = p.run(method, param, horizon, truth.times);
  const run_metrics m = measure(p, r, truth);
  out.k = adaptive ? static_cast<int>(std::lround(static_cast<double>(r.steps) / (horizon * hz))) : k;
  out.completed = m.completed();
  out.err = m.err_pos_max;
  out.note = m.note;
  if (!out.completed) return out;
  const std::vector<double> end{horizon};
  auto once = p.timed_run(method, param, horizon, adaptive ? truth.times : end);
  volatile double sink = 0.0;
  out.ns_per_frame = median_ns([&] { sink = sink + once(); }) / (horizon * hz);
  return out;
}

// The link-length error of xpbd with `substeps` a frame: max over frame ends of max_j |C_j| / l.
double xpbd_link_error(const n_pendulum& p, double hz, int substeps, double horizon) {
  const auto s0 = p.initial();
  xpbd_solver s(p.particles(s0.x, s0.v));
  double worst = 0.0;
  const long frames = std::lround(horizon * hz);
  for (long f = 0; f < frames; ++f) {
    for (int k = 0; k < substeps; ++k) s.step(1.0 / (hz * substeps), 1);
    worst = std::max(worst, constraint_violation(s.s));
  }
  return worst;
}

// |C_j(a) - C_j(b)| / L_j, the largest over the constraints (same particles and constraints).
double link_error(const particle_system& a, const particle_system& b) {
  double worst = 0.0;
  for (const auto& c : a.constraints)
    worst = std::max(worst, std::abs(constraint_length(a, c) - constraint_length(b, c)) / c.rest_length);
  return worst;
}

template <class P>
std::vector<double> observed_positions(const P& p, const typename P::vec& x) {
  if constexpr (has_observed_positions<P>) {
    Eigen::VectorXd pos(p.observed_dim()), vel(p.observed_dim());
    const typename P::vec v = P::vec::Zero(p.dim());
    p.observe(x, v, pos, vel);
    return {pos.data(), pos.data() + pos.size()};
  } else {
    return {x.data(), x.data() + x.size()};
  }
}

// The positions a run draws: its own particles' where it steps them (xpbd, `own`) on a
// problem that observes its positions, else its state's observed ones.
template <class P>
std::vector<double> drawn_positions(const P& p, const typename P::vec& x, const particle_system* own) {
  if constexpr (has_drawn_particles<P>) {
    if (own) {
      Eigen::VectorXd pos(p.observed_dim()), vel(p.observed_dim());
      p.observe_particles(*own, pos, vel);
      return {pos.data(), pos.data() + pos.size()};
    }
  }
  return observed_positions(p, x);
}

// The Small Steps rows of one problem: every design at every n, at t = time.
template <class P>
void small_steps_of(const P& p, const challenge_options& o, std::vector<small_steps_row>& rows) {
  auto inst = make_problem(P::name);
  for (const auto& q : P::parameters()) inst->set(q.name, p.*q.member);
  const truth_table truth = build_truth(*inst, std::vector<double>{o.small_steps_time}, {});
  const auto dim = static_cast<Eigen::Index>(p.dim());
  const typename P::vec x_true = Eigen::Map<const Eigen::VectorXd>(truth.y[0].data(), dim);
  const typename P::vec v_true = Eigen::Map<const Eigen::VectorXd>(truth.y[0].data() + dim, dim);
  const particle_system true_particles = p.particles(x_true, v_true);
  const auto true_pos = observed_positions(p, x_true);
  const int body_dim = inst->body_dim();
  const double frames = o.small_steps_time * o.hz, frame = 1.0 / o.hz;
  const auto s0 = p.initial();

  // The link error from the particles a method ends with: XPBD's own (its links may
  // stretch), or the view of a force-based method's state.
  auto finish = [&](small_steps_row r, const typename P::vec& x, const typename P::vec& v,
                    const particle_system* own = nullptr) {
    const int n = static_cast<int>(true_pos.size());
    r.err_pos = all_finite(x, v) ? worst_body(drawn_positions(p, x, own), 0, n, body_dim, true_pos) : nan;
    r.diverged = !(r.err_pos <= blowup_factor * truth.pos_scale);
    r.link_err = r.diverged ? nan : link_error(own ? *own : p.particles(x, v), true_particles);
    rows.push_back(std::move(r));
  };
  particle_system last;
  auto xpbd_run = [&](int substeps, int passes, typename P::vec& x, typename P::vec& v) {
    xpbd_solver s(p.particles(s0.x, s0.v));
    for (long f = 0; f < std::lround(frames); ++f)
      for (int k = 0; k < substeps; ++k) s.step(frame / substeps, passes);
    p.from_particles(s.s, x, v);
    last = s.s;
  };
  typename P::vec x = s0.x, v = s0.v;
  const small_steps_designs design;
  for (int n : o.small_steps_counts) {
    small_steps_row r{.problem = std::string(P::name),
                      .design = design.xpbd_substeps,
                      .n = n,
                      .work_per_frame = static_cast<double>(n)};
    r.ns_per_frame = median_ns([&] { xpbd_run(n, 1, x, v); }, 3) / frames;
    finish(r, x, v, &last);
    r.design = design.xpbd_passes;
    r.ns_per_frame = median_ns([&] { xpbd_run(1, n, x, v); }, 3) / frames;
    finish(r, x, v, &last);
    r.design = design.explicit_substeps;
    drive_result<typename P::vec> d;
    r.ns_per_frame =
        median_ns([&] { d = drive(p, semi_implicit_euler{}, frame / n, o.small_steps_time, {}); }, 3) / frames;
    finish(r, d.final_state.x, d.final_state.v);
  }
  drive_result<typename P::vec> d;
  small_steps_row r{.problem = std::string(P::name), .design = design.implicit_step, .n = 1};
  r.ns_per_frame = median_ns([&] { d = drive(p, implicit_euler{}, frame, o.small_steps_time, {}); }, 3) / frames;
  r.work_per_frame = static_cast<double>(d.work.force_evals) / frames;
  finish(r, d.final_state.x, d.final_state.v);
}

std::string small_steps_verdict(const std::vector<small_steps_row>& rows, const std::string& problem) {
  auto find = [&](const std::string& design, int n) -> const small_steps_row* {
    for (const auto& r : rows)
      if (r.problem == problem && r.design == design && r.n == n) return &r;
    return nullptr;
  };
  const small_steps_designs design;
  const small_steps_row* ie = find(design.implicit_step, 1);
  int n_max = 0;
  for (const auto& r : rows)
    if (r.problem == problem) n_max = std::max(n_max, r.n);
  const auto* sub = find(design.xpbd_substeps, n_max);
  const auto* it = find(design.xpbd_passes, n_max);
  const auto* sie = find(design.explicit_substeps, n_max);
  if (!ie || !sub || !it || !sie) return problem + ": incomplete";
  auto err = [](const small_steps_row& r) {
    return r.diverged ? std::string("diverged") : fmt::format("{:.3g} m (links {:.2g})", r.err_pos, r.link_err);
  };
  return fmt::format(
      "{}: at {} passes a frame, {} substeps of one XPBD pass: {} in {:.3g} us a frame; one step of {} passes: {} "
      "in {:.3g} us; {} semi-implicit Euler substeps: {} in {:.3g} us; one implicit Euler step ({:.3g} force "
      "evaluations): {} in {:.3g} us",
      problem, n_max, n_max, err(*sub), sub->ns_per_frame / 1e3, n_max, err(*it), it->ns_per_frame / 1e3, n_max,
      err(*sie), sie->ns_per_frame / 1e3, ie->work_per_frame, err(*ie), ie->ns_per_frame / 1e3);
}

// log-log interpolation of the time per frame at error `target` on a method's measured
// points (k increasing): between the last point above the target and the first at or below.
double time_at_error(const std::vector<ladder_point>& pts, double target) {
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i].completed || !(pts[i].err <= target)) continue;
    if (i == 0 || !pts[i - 1].completed) return pts[i].ns_per_frame;
    const auto& a = pts[i - 1];
    const auto& b = pts[i];
    const double f = (std::log(target) - std::log(a.err)) / (std::log(b.err) - std::log(a.err));
    return std::exp(std::log(a.ns_per_frame) + f * (std::log(b.ns_per_frame) - std::log(a.ns_per_frame)));
  }
  return nan;
}

}  // namespace

challenge_result run_challenge(const challenge_options& o, void (*progress)(const std::string&)) {
  const auto start = std::chrono::steady_clock::now();
  challenge_result out;
  out.options = o;
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  n_pendulum scene;
  auto p = make_problem(n_pendulum::name);
  const truth_table truth = build_truth(*p, frame_ends(o.hz, o.horizon), {});
  const double n = scene.links;
  out.energy_scale = scene.mass_kg * scene.gravity * scene.length_m * n * (n + 1) / 2;
  const double e0 = p->energy(p->initial());
  const auto energy_times = frame_ends(1.0, o.energy_horizon);

  auto energy_of = [&](challenge_entry& e, const std::string& method, double dt) {
    const run_result r = p->run(method, dt, o.energy_horizon, energy_times);
    if (r.non_finite || !r.stop_reason.empty() || r.sample_y.size() != energy_times.size()) {
      e.stable = false;
      e.energy_drift = e.energy_err_max = nan;
      e.note = r.non_finite ? "non-finite state within the energy horizon" : r.stop_reason;
      return;
    }
    for (const auto& y : r.sample_y) e.energy_err_max = std::max(e.energy_err_max, std::abs(p->energy(y) - e0));
    e.energy_err_max /= out.energy_scale;
    e.energy_drift = (p->energy(r.sample_y.back()) - e0) / out.energy_scale;
    e.stable = e.energy_err_max < 1.0;
    if (!e.stable) e.note = "the energy error reached the energy scale";
  };

  const std::string xpbd_name = xpbd::describe().name;
  say("challenge: " + xpbd_name);
  const ladder_point xp = measure_at(*p, truth, xpbd_name, o.xpbd_substeps, o.hz, o.horizon);
  challenge_entry x{.method = xpbd_name,
                    .steps_per_frame = o.xpbd_substeps,
                    .ns_per_frame = xp.ns_per_frame,
                    .err_pos_max = xp.err,
                    .note = xp.note};
  x.link_err_max = xpbd_link_error(scene, o.hz, o.xpbd_substeps, o.horizon);
  energy_of(x, xpbd_name, 1.0 / (o.hz * o.xpbd_substeps));
  x.ns_per_frame_at_xpbd_error = x.ns_per_frame;
  out.entries.push_back(x);

  for (const auto& method : o.competitors) {
    say("challenge: " + method);
    std::vector<ladder_point> pts;  // in increasing cost
    ladder_point at;
    if (find_method(method).kind == method_kind::adaptive) {
      // Tolerances 1e-1, 1e-2, ... until the error is xpbd's or smaller (the speed
      // curve) and the time is past xpbd's (the accuracy at equal time: the tightest
      // tolerance whose measured time per frame is at most xpbd's; the loosest when none is).
      for (int e = 1; e <= 13; ++e) {
        pts.push_back(measure_at(*p, truth, method, 0, o.hz, o.horizon, std::pow(10.0, -e)));
        const auto& b = pts.back();
        if (b.completed && b.err <= x.err_pos_max && b.ns_per_frame > x.ns_per_frame) break;
      }
      at = pts.front();
      for (const auto& q : pts)
        if (q.completed && q.ns_per_frame <= x.ns_per_frame) at = q;
    } else {
      // Steps a frame 1, 2, 4, ... until the error is xpbd's or smaller (the speed curve).
      for (int k = 1; k <= 1 << 12; k *= 2) {
        pts.push_back(measure_at(*p, truth, method, k, o.hz, o.horizon));
        if (pts.back().completed && pts.back().err <= x.err_pos_max) break;
      }
      // At xpbd's time per frame: the most whole steps whose time is at most xpbd's,
      // from the time of one step a frame (time is linear in the steps).
      const double one = pts.front().completed ? pts.front().ns_per_frame : nan;
      const int k_equal = std::isfinite(one) ? std::max(1, static_cast<int>(std::floor(x.ns_per_frame / one))) : 1;
      at = measure_at(*p, truth, method, k_equal, o.hz, o.horizon);
    }
    challenge_entry e{.method = method,
                      .steps_per_frame = at.k,
                      .tolerance = at.tolerance,
                      .ns_per_frame = at.ns_per_frame,
                      .err_pos_max = at.completed ? at.err : nan,
                      .note = at.note};
    e.stable = at.completed;
    // Its cheapest setting (one step a frame, tolerance 1e-1) may already cost more than
    // xpbd's frame: then it is not an entry at xpbd's time, and the verdict says so.
    e.over_xpbd_time = at.completed && at.ns_per_frame > x.ns_per_frame;
    if (e.stable) energy_of(e, method, std::isfinite(at.tolerance) ? at.tolerance : 1.0 / (o.hz * at.k));
    e.ns_per_frame_at_xpbd_error = time_at_error(pts, x.err_pos_max);
    out.entries.push_back(e);
  }

  // The verdicts, one a criterion.
  const auto& xe = out.entries.front();
  const challenge_entry* most_accurate = &xe;
  const challenge_entry* fastest = &xe;
  for (const auto& e : out.entries) {
    if (!e.over_xpbd_time && e.err_pos_max < most_accurate->err_pos_max) most_accurate = &e;
    if (e.ns_per_frame_at_xpbd_error < fastest->ns_per_frame_at_xpbd_error) fastest = &e;
  }
  std::string acc = fmt::format("accuracy at xpbd's {:.3g} us a frame: ", xe.ns_per_frame / 1e3);
  for (const auto& e : out.entries) {
    acc += fmt::format("{}{} {} {:.3g} m", &e == &xe ? "" : ", ", e.method,
                       std::isfinite(e.tolerance)
                           ? fmt::format("tol {:.0e} ({} steps a frame)", e.tolerance, e.steps_per_frame)
                           : fmt::format("x{}", e.steps_per_frame),
                       e.err_pos_max);
    if (e.over_xpbd_time) acc += fmt::format(" (over xpbd's time: {:.3g} us)", e.ns_per_frame / 1e3);
  }
  acc += fmt::format(" (bobs' largest error over {:g} s); most accurate: {}", o.horizon, most_accurate->method);
  std::string stab = fmt::format("stability over {:g} s: ", o.energy_horizon);
  for (const auto& e : out.entries)
    stab += fmt::format("{}{} {}", &e == &xe ? "" : ", ", e.method,
                        e.stable ? fmt::format("energy drift {:+.2e}", e.energy_drift) : "unstable: " + e.note);
  stab += fmt::format(" (of m g l N(N+1)/2 = {:.3g} J); xpbd's links stay within {:.1e} of their length",
                      out.energy_scale, xe.link_err_max);
  std::string speed = fmt::format("speed at xpbd's error ({:.3g} m): ", xe.err_pos_max);
  for (const auto& e : out.entries)
    speed += fmt::format("{}{} {}", &e == &xe ? "" : ", ", e.method,
                         std::isfinite(e.ns_per_frame_at_xpbd_error)
                             ? fmt::format("{:.3g} us a frame", e.ns_per_frame_at_xpbd_error / 1e3)
                             : std::string("not reached"));
  speed += fmt::format("; fastest: {}", fastest->method);
  out.verdict_criteria = {"accuracy", "stability", "speed"};
  out.verdicts = {acc, stab, speed};

  say("small steps: n_pendulum");
  small_steps_of(scene, o, out.small_steps);
  say("small steps: spring_chain");
  small_steps_of(spring_chain{}, o, out.small_steps);
  out.small_steps_verdicts = {small_steps_verdict(out.small_steps, std::string(n_pendulum::name)),
                              small_steps_verdict(out.small_steps, std::string(spring_chain::name))};
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace stepbench

#include "study/verdict.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "core/contains.hpp"
#include "core/number.hpp"
#include "core/work_precision.hpp"
#include "study/h5.hpp"
#include "study/loop.hpp"
#include "study/study_file.hpp"
#include "study/substeps.hpp"
#include "study/table_render.hpp"

namespace stepbench {
namespace {

constexpr const char* metric = "err_pos_max";

std::string hz_text(double hz) { return fmt::format("{:g} Hz", hz); }

// "rk4 x4" for four substeps, "rk4" for one.
std::string with_substeps(const std::string& method, int n) {
  return n == 1 ? method : fmt::format("{} x{}", method, n);
}

}  // namespace

truth_table every_nth(const truth_table& t, std::size_t stride) {
  truth_table out = t;
  out.times.clear();
  out.y.clear();
  for (std::size_t j = stride - 1; j < t.times.size(); j += stride) {
    out.times.push_back(t.times[j]);
    out.y.push_back(t.y[j]);
  }
  return out;
}

std::vector<double> verdict_targets() { return equal_error_targets(); }

std::vector<frame_rate_study> run_frame_rates(const study& s, const frame_rate_options& opts) {
  std::vector<frame_rate_study> out;
  if (opts.hz.empty()) return out;
  const double slowest = *std::min_element(opts.hz.begin(), opts.hz.end());
  const double fastest = *std::max_element(opts.hz.begin(), opts.hz.end());
  const double finest_target = verdict_targets().back();
  for (const auto& ps : s.problems) {
    if (!ps.truth.trusted) continue;
    // Whole frames of the slowest rate; every rate divides the fastest, so the truth at
    // the fastest rate's frame ends holds every rate's.
    const long slow_frames = static_cast<long>(std::floor(ps.horizon * slowest * (1.0 + 1e-12)));
    if (slow_frames < 1) continue;
    frame_rate_study fs;
    fs.problem = std::string(ps.problem->name());
    fs.unit = std::string(ps.problem->position_unit());
    fs.horizon = static_cast<double>(slow_frames) / slowest;
    const long fast_frames = std::lround(fs.horizon * fastest);
    std::vector<double> times;
    for (long j = 1; j <= fast_frames; ++j) times.push_back(static_cast<double>(j) / fastest);
    const truth_table fine = build_truth(*ps.problem, times, {.tol = s.options.tol});
    if (!fine.trusted) continue;
    for (double hz : opts.hz) {
      const auto stride = static_cast<std::size_t>(std::lround(fastest / hz));
      const truth_table truth = every_nth(fine, stride);
      for (const auto& info : ps.problem->methods()) {
        if (info.origin != method_origin::ours || info.kind != method_kind::fixed_step) continue;
        if (!s.options.methods.empty() && !contains(s.options.methods, info.name)) continue;
        for (int n : opts.substeps) {
          const double dt = 1.0 / (hz * n);
          const run_result run = ps.problem->run(info.name, dt, fs.horizon, truth.times, s.options.limits);
          frame_rate_run r{
              hz, info.name, n, {dt, run.steps, run.rejected_steps, run.work, measure(*ps.problem, run, truth), {}}};
          const bool done =
              r.row.metrics.skipped || (r.row.metrics.completed() && r.row.metrics.err_pos_max <= finest_target);
          fs.runs.push_back(std::move(r));
          if (done) break;  // over the work budget, or already at the finest target
        }
      }
    }
    if (s.options.progress) std::fprintf(stderr, "frame rates %-20s %zu runs\n", fs.problem.c_str(), fs.runs.size());
    out.push_back(std::move(fs));
  }
  return out;
}

namespace {

// The cost of a frame of a run: the measured ns per step times the steps of a frame
// (timed), else the force evaluations of a frame.
double cost_per_frame(const problem_study* ps, const frame_rate_study& fs, const frame_rate_run& r, bool timed) {
  const double frames = fs.horizon * r.hz;
  if (!timed) return static_cast<double>(r.row.work.force_evals) / frames;
  const double ns = ps ? measured_step_cost_ns(*ps, r.method) : nan;
  return std::isfinite(ns) && ns > 0.0 ? ns * r.substeps : nan;
}

const problem_study* find_problem(const study& s, std::string_view name) {
  for (const auto& ps : s.problems)
    if (ps.problem->name() == name) return &ps;
  return nullptr;
}

cost_at_error cost_of(const std::vector<wp_method>& methods, const wp_pick* p) {
  if (!p) return {};
  const auto& m = methods[p->method];
  return {m.name, std::string(to_string(m.kind)), p->param, p->cost, p->cost_lo, p->cost_hi, p->interpolated};
}

std::string verdict_of(const cost_at_error& ours, const cost_at_error& peer, bool timed) {
  if (!ours.found() && !peer.found()) return "not reached";
  if (!peer.found()) return "ours only";
  if (!ours.found()) return "peers only";
  const std::string v =
      compare_at_equal_error({ours.cost, ours.cost_lo, ours.cost_hi}, {peer.cost, peer.cost_lo, peer.cost_hi}, timed);
  // An upper bound on the side found cheaper proves nothing: its true cost may be lower.
  if ((v == "ahead" && !peer.interpolated) || (v == "behind" && !ours.interpolated)) return "bounded";
  return v;
}

std::string cost_text(const std::string& kind, double c) {
  if (!std::isfinite(c)) return "-";
  return kind == "time_ns" ? format_time_ns(c) : fmt::format("{:.3g} evals", c);
}

}  // namespace

// The findings: one sentence each, from the verdicts just computed and the studies'.
std::vector<std::string> findings_of(const verdict_tables& v, const finding_inputs& in) {
  std::vector<std::string> out;
  const bool timed = v.cost_kind == "time_ns";
  // Equal error.
  {
    int ahead = 0, behind = 0, within = 0, bounded = 0, ours_only = 0, peers_only = 0;
    const equal_error_verdict* best_win = nullptr;
    const equal_error_verdict* worst_loss = nullptr;
    for (const auto& e : v.equal_error) {
      if (e.verdict == "ahead") ++ahead;
      if (e.verdict == "behind") ++behind;
      if (e.verdict == "within spread") ++within;
      if (e.verdict == "bounded") ++bounded;
      if (e.verdict == "ours only") ++ours_only;
      if (e.verdict == "peers only") ++peers_only;
      if (e.verdict == "ahead" && (!best_win || e.ratio < best_win->ratio)) best_win = &e;
      if (e.verdict == "behind" && (!worst_loss || e.ratio > worst_loss->ratio)) worst_loss = &e;
    }
    std::string line = fmt::format(
        "At equal error ({}, interpolated on each method's measured curve), the fastest of ours against the "
        "fastest library peer: ahead on {}, behind on {}, within the {} on {}, undecided on {} (the side found "
        "cheaper only bounded: its ladder does not bracket the target) of the {} problem-and-target pairs both "
        "reach; only ours reach {}, only a peer {}.",
        timed ? "measured time" : "force evaluations", ahead, behind, timed ? "timing noise" : "rounding", within,
        bounded, ahead + behind + within + bounded, ours_only, peers_only);
    if (best_win)
      line += fmt::format(" Largest lead: {} on {} at {:g} {} ({:.2g}x the {} of {}).", best_win->ours.method,
                          best_win->problem, best_win->target, best_win->unit, best_win->ratio,
                          timed ? "time" : "force evaluations", best_win->peer.method);
    if (worst_loss)
      line += fmt::format(" Largest deficit: {} on {} at {:g} {} ({:.2g}x {}).", worst_loss->ours.method,
                          worst_loss->problem, worst_loss->target, worst_loss->unit, worst_loss->ratio,
                          worst_loss->peer.method);
    out.push_back(line);
  }
  // Implicit step against substeps.
  for (const auto& [problem, frame_dt, sv] : in.substeps) {
    const int n = sv.substeps_at_equal_cost;
    std::string line = fmt::format("{} (frame {:.3g} s): ", problem, frame_dt);
    if (n == 0 && sv.cost_kind == "time_ns")
      line +=
          "no timed semi_implicit_euler run costs as little as one implicit_euler step (the substep counts "
          "that diverge are not timed)";
    else if (n == 0)
      line += "even one semi_implicit_euler substep costs more than one implicit_euler step";
    else if (!std::isfinite(sv.explicit_error))
      line += fmt::format("one implicit_euler step costs as much as {} semi_implicit_euler substep{}, which diverge{}",
                          n, n == 1 ? "" : "s", n == 1 ? "s" : "");
    else if (sv.explicit_error <= sv.implicit_error)
      line += fmt::format(
          "{} semi_implicit_euler substep{} cost as much as one implicit_euler step and are {:.2g}x "
          "more accurate",
          n, n == 1 ? "" : "s", sv.implicit_error / sv.explicit_error);
    else
      line += fmt::format(
          "{} semi_implicit_euler substep{} cost as much as one implicit_euler step and are {:.2g}x "
          "less accurate",
          n, n == 1 ? "" : "s", sv.explicit_error / sv.implicit_error);
    if (sv.substeps_to_match > 0) line += fmt::format("; {} substeps match its error", sv.substeps_to_match);
    out.push_back(line + ".");
  }
  // Declared orders that do not hold.
  {
    const auto& broken = in.broken_orders;
    if (!broken.empty()) {
      std::string names;
      for (const auto& [m, ps] : broken)
        names +=
            fmt::format("{}{} on {} problem{}", names.empty() ? "" : ", ", m, ps.size(), ps.size() == 1 ? "" : "s");
      out.push_back(
          fmt::format("Library methods whose observed order differs from the order they declare: {}.", names));
    } else {
      out.push_back("Every library method's observed order matches its declared order where it can be fitted.");
    }
  }
  // xpbd's stability and energy over its dt ladder (at a 60 Hz frame, the substep
  // ladder): the claim that rigid links stay stable at every substep count, and
  // XPBD's projection only removing energy, as the study's own runs show them. The energy
  // is the run's at its end (energy_drift), not its largest excursion: the text says so.
  {
    std::string parts;
    for (const auto& [problem, runs] : in.xpbd_ladders) {
      int ran = 0, completed = 0, diverged = 0, failed = 0;
      double dt_max = 0.0, dt_min = std::numeric_limits<double>::infinity();
      const ladder_run *coarsest = nullptr, *finest = nullptr;  // of the completed runs
      double largest_drift = -std::numeric_limits<double>::infinity(), worst_constraint = nan;
      for (const auto& r : runs) {
        if (r.skipped) continue;
        ++ran;
        dt_max = std::fmax(dt_max, r.dt);
        dt_min = std::fmin(dt_min, r.dt);
        diverged += r.diverged;
        failed += r.failed && !r.diverged;
        if (!row_completed(r.diverged, r.failed, r.skipped)) continue;
        ++completed;
        if (!coarsest || r.dt > coarsest->dt) coarsest = &r;
        if (!finest || r.dt < finest->dt) finest = &r;
        largest_drift = std::fmax(largest_drift, r.energy_drift);  // fmax drops a NaN
        worst_constraint = std::fmax(worst_constraint, r.constraint_violation);
      }
      if (ran == 0) continue;  // every rung over the work budget: nothing to say of it
      std::string part = fmt::format("{} completed {} of the {} dt it ran ({} to {})", problem, completed, ran,
                                     format_time_ns(dt_max * 1e9), format_time_ns(dt_min * 1e9));
      if (diverged > 0) part += fmt::format(", diverged at {}", diverged);
      if (failed > 0) part += fmt::format(", failed at {}", failed);
      // A merged file may lack a drift (NaN): say only the numbers the runs have.
      if (coarsest && std::isfinite(coarsest->energy_drift) && std::isfinite(finest->energy_drift))
        part += fmt::format(", final energy drift {:.2g} at {} and {:.2g} at {} (largest {:.2g})",
                            coarsest->energy_drift, format_time_ns(coarsest->dt * 1e9), finest->energy_drift,
                            format_time_ns(finest->dt * 1e9), largest_drift);
      if (std::isfinite(worst_constraint)) part += fmt::format(", |C|/L within {:.2g}", worst_constraint);
      parts += (parts.empty() ? "" : "; ") + part;
    }
    if (!parts.empty())
      out.push_back(fmt::format(
          "xpbd over its dt ladder (final energy drift: the energy at the run's end against the truth's, of the "
          "problem's energy scale, at the coarsest and the finest completed dt and the largest over the completed; "
          "|C|/L: the largest relative length error of a rigid link, the stretch of a spring, over the run): {}.",
          parts));
  }
  // Stability at 60 Hz, one step a frame.
  {
    std::map<std::string, std::vector<std::string>> unstable;  // problem -> methods
    for (const auto& f : v.frame_rate)
      if (f.hz == 60.0 && !f.stable) unstable[f.problem].push_back(f.method);
    const bool any_60 =
        std::any_of(v.frame_rate.begin(), v.frame_rate.end(), [](const auto& f) { return f.hz == 60.0; });
    if (!any_60) {
    } else if (unstable.empty()) {
      out.push_back("At 60 Hz, one step a frame, every fixed-step method of ours stays stable on every problem.");
    } else {
      std::string parts;
      for (const auto& [p, ms] : unstable)
        parts += fmt::format("{}{}: {}", parts.empty() ? "" : "; ", p, fmt::join(ms, ", "));
      out.push_back(fmt::format("At 60 Hz, one step a frame, these diverge or fail: {}.", parts));
    }
  }
  return out;
}

finding_inputs finding_inputs_of(const study& s) {
  finding_inputs in;
  for (const auto& st : s.results.get<std::vector<substep_study>>())
    for (const auto& sv : substep_verdicts(st, s.timed.has_value()))
      if (sv.implicit_method == "implicit_euler" && sv.explicit_method == "semi_implicit_euler")
        in.substeps.push_back({st.problem, st.frame_dt, sv});
  for (const auto& ps : s.problems)
    for (const auto& ms : ps.methods)
      if (ms.info.origin == method_origin::peer && ms.declared_order_holds == 0)
        in.broken_orders[ms.info.name].insert(std::string(ps.problem->name()));
  for (const auto& ps : s.problems)
    for (const auto& ms : ps.methods) {
      if (ms.info.name != "xpbd") continue;
      ladder_finding f{std::string(ps.problem->name()), {}};
      for (const auto& r : ms.rows) {
        const auto& m = r.metrics;
        f.runs.push_back({r.param, m.diverged, m.failed, m.skipped, m.energy_drift, m.constraint_violation_max});
      }
      in.xpbd_ladders.push_back(std::move(f));
    }
  return in;
}

finding_inputs read_finding_inputs(const H5::Group& root, const std::vector<std::string>& problems) {
  finding_inputs in;
  for (const auto& p : problems) {
    if (h5::is_group(root, "substeps/" + p)) {
      const H5::Group g = root.openGroup("substeps/" + p);
      const double frame_dt = h5::double_attr(g, "frame_dt");
      const auto t = h5::read_table(g.openDataSet("verdict"));
      const auto &im = t.strings("implicit_method"), &em = t.strings("explicit_method"), &kind = t.strings("cost_kind"),
                 &summary = t.strings("summary");
      const auto ic = t.doubles("implicit_cost"), ie = t.doubles("implicit_error"), id = t.doubles("implicit_damping"),
                 ec = t.doubles("explicit_cost"), ee = t.doubles("explicit_error"), ed = t.doubles("explicit_damping"),
                 ctm = t.doubles("cost_to_match");
      const auto &at_cost = t.ints("substeps_at_equal_cost"), &to_match = t.ints("substeps_to_match");
      for (std::size_t i = 0; i < t.rows(); ++i)
        if (im[i] == "implicit_euler" && em[i] == "semi_implicit_euler")
          in.substeps.push_back(
              {p, frame_dt,
               substep_verdict{p, im[i], em[i], kind[i], ic[i], ie[i], id[i], static_cast<int>(at_cost[i]), ec[i],
                               ee[i], ed[i], static_cast<int>(to_match[i]), ctm[i], summary[i]}});
    }
    if (h5::is_group(root, "problems/" + p + "/methods")) {
      const H5::Group methods = root.openGroup("problems/" + p + "/methods");
      for (const auto& m : h5::children(methods)) {
        const H5::Group g = methods.openGroup(m);
        if (h5::string_attr(g, "origin") == "peer" && h5::long_attr(g, "declared_order_holds") == 0)
          in.broken_orders[m].insert(p);
      }
      if (h5::is_group(methods, "xpbd")) {
        const auto t = h5::read_table(methods.openGroup("xpbd").openDataSet("runs"));
        const auto dt = t.doubles("param"), drift = t.doubles("energy_drift");
        // A study written before the field reads as NaN (as study_reader.cpp does).
        const auto constraint = t.has("constraint_violation_max") ? t.doubles("constraint_violation_max")
                                                                  : std::vector<double>(t.rows(), nan);
        const auto &diverged = t.ints("diverged"), &failed = t.ints("failed"), &skipped = t.ints("skipped");
        ladder_finding f{p, {}};
        for (std::size_t i = 0; i < t.rows(); ++i)
          f.runs.push_back({dt[i], diverged[i] != 0, failed[i] != 0, skipped[i] != 0, drift[i], constraint[i]});
        in.xpbd_ladders.push_back(std::move(f));
      }
    }
  }
  return in;
}

verdict_tables compute_verdict(const study& s) {
  verdict_tables v;
  const bool timed = s.timed.has_value();
  v.cost_kind = timed ? "time_ns" : "force_evals";
  for (const auto& ps : s.problems) {
    const auto methods = work_precision_input(ps, metric);
    const std::string unit(ps.problem->position_unit());
    double best_error = std::numeric_limits<double>::infinity();
    for (const auto& m : methods)
      if (m.origin != method_origin::baseline)
        for (const auto& r : m.rows)
          if (r.completed && std::isfinite(r.error)) best_error = std::min(best_error, r.error);
    for (double target : verdict_targets()) {
      const auto r = cheapest(methods, target, timed, metric, unit,
                              timed ? wp_candidates::timed_methods : wp_candidates::every_method);
      const wp_pick *ours = nullptr, *peer = nullptr;
      for (const auto& p : r.ranked) {
        if (methods[p.method].origin == method_origin::ours && !ours) ours = &p;
        if (methods[p.method].origin == method_origin::peer && !peer) peer = &p;
      }
      equal_error_verdict e;
      e.problem = std::string(ps.problem->name());
      e.unit = unit;
      e.target = target;
      e.ours = cost_of(methods, ours);
      e.peer = cost_of(methods, peer);
      e.ratio = ours && peer ? ours->cost / peer->cost : nan;
      e.cost_kind = r.cost;
      e.verdict = verdict_of(e.ours, e.peer, r.cost == "time_ns");
      e.best_error = std::isfinite(best_error) ? best_error : nan;
      v.equal_error.push_back(std::move(e));
    }
  }
  for (const auto& fs : s.results.get<std::vector<frame_rate_study>>()) {
    const problem_study* ps = find_problem(s, fs.problem);
    std::vector<double> rates;
    for (const auto& r : fs.runs)
      if (std::find(rates.begin(), rates.end(), r.hz) == rates.end()) rates.push_back(r.hz);
    for (double hz : rates) {
      for (const auto& r : fs.runs) {
        if (r.hz != hz || r.substeps != 1) continue;
        const auto& m = r.row.metrics;
        v.frame_rate.push_back({fs.problem, fs.unit, r.method, m.completed() ? "" : (m.diverged ? "diverged" : m.note),
                                hz, m.completed(), m.completed() ? m.err_pos_max : nan});
      }
      for (double target : verdict_targets()) {
        frame_answer a{fs.problem, fs.unit, "", hz, target, 0, nan, nan, nan};
        for (const auto& r : fs.runs) {
          if (r.hz != hz || !r.row.metrics.completed() || !(r.row.metrics.err_pos_max <= target)) continue;
          const double c = cost_per_frame(ps, fs, r, timed);
          if (!std::isfinite(c)) continue;
          if (a.method.empty() || c < a.cost_per_frame ||
              (c == a.cost_per_frame && r.row.metrics.err_pos_max < a.err_pos_max)) {
            a.method = r.method;
            a.substeps = r.substeps;
            a.err_pos_max = r.row.metrics.err_pos_max;
            a.cost_per_frame = c;
            a.frame_share = timed ? c / (1e9 / hz) : nan;
          }
        }
        v.frame_answers.push_back(std::move(a));
      }
    }
  }
  v.findings = findings_of(v, finding_inputs_of(s));
  return v;
}

void write_verdict(H5::Group& root, const study& s) {
  using h5::attr;
  const verdict_tables* found = s.results.find<verdict_tables>();
  if (!found) return;
  const verdict_tables& v = *found;
  H5::Group g = root.createGroup("verdict");
  attr(g, "metric", metric);
  attr(g, "targets", verdict_targets());
  attr(g, "frame_hz", s.options.frame_rates.hz);
  attr(g, "cost_kind", v.cost_kind);
  std::string findings;
  for (const auto& f : v.findings) findings += (findings.empty() ? "" : "\n") + f;
  attr(g, "findings", findings);
  attr(g, "rule",
       "time (or force evaluations) at equal error, interpolated log-log between the two measured rows that bracket "
       "the target on each method's work-precision curve, never extrapolated; ahead or behind only when the ratio "
       "lies outside the timing noise: the larger of 15 % (25 % from one repetition) and 3 x the repetitions' "
       "relative spread, the band stepbench compare uses between two runs");
  {
    std::vector<std::string> problem, unit, om, ok, pm, pk, verdict, cost_kind;
    std::vector<double> target, op, oc, ol, oh, pp, pc, pl, ph, ratio, best;
    std::vector<std::int8_t> oi, pi;
    for (const auto& e : v.equal_error) {
      problem.push_back(e.problem);
      unit.push_back(e.unit);
      target.push_back(e.target);
      om.push_back(e.ours.method);
      ok.push_back(e.ours.kind);
      op.push_back(e.ours.found() ? e.ours.param : nan);
      oc.push_back(e.ours.found() ? e.ours.cost : nan);
      ol.push_back(e.ours.found() ? e.ours.cost_lo : nan);
      oh.push_back(e.ours.found() ? e.ours.cost_hi : nan);
      oi.push_back(static_cast<std::int8_t>(e.ours.interpolated));
      pm.push_back(e.peer.method);
      pk.push_back(e.peer.kind);
      pp.push_back(e.peer.found() ? e.peer.param : nan);
      pc.push_back(e.peer.found() ? e.peer.cost : nan);
      pl.push_back(e.peer.found() ? e.peer.cost_lo : nan);
      ph.push_back(e.peer.found() ? e.peer.cost_hi : nan);
      pi.push_back(static_cast<std::int8_t>(e.peer.interpolated));
      ratio.push_back(e.ratio);
      cost_kind.push_back(e.cost_kind);
      verdict.push_back(e.verdict);
      best.push_back(e.best_error);
    }
    h5::table t;
    t.add("problem", problem);
    t.add("unit", unit);
    t.add("target", target);
    t.add("ours_method", om);
    t.add("ours_kind", ok);
    t.add("ours_param", op);
    t.add("ours_cost", oc);
    t.add("ours_cost_lo", ol);
    t.add("ours_cost_hi", oh);
    t.add("ours_interpolated", oi);
    t.add("peer_method", pm);
    t.add("peer_kind", pk);
    t.add("peer_param", pp);
    t.add("peer_cost", pc);
    t.add("peer_cost_lo", pl);
    t.add("peer_cost_hi", ph);
    t.add("peer_interpolated", pi);
    t.add("ratio", ratio);
    t.add("cost_kind", cost_kind);
    t.add("verdict", verdict);
    t.add("best_error", best);
    t.write(g, "equal_error", schema::find("verdict_equal_error"));
  }
  {
    std::vector<std::string> problem, unit, method, note;
    std::vector<double> hz, err;
    std::vector<std::int8_t> stable;
    for (const auto& f : v.frame_rate) {
      problem.push_back(f.problem);
      unit.push_back(f.unit);
      hz.push_back(f.hz);
      method.push_back(f.method);
      stable.push_back(static_cast<std::int8_t>(f.stable));
      err.push_back(f.err_pos_max);
      note.push_back(f.note);
    }
    h5::table t;
    t.add("problem", problem);
    t.add("unit", unit);
    t.add("hz", hz);
    t.add("method", method);
    t.add("stable", stable);
    t.add("err_pos_max", err);
    t.add("note", note);
    t.write(g, "frame_rate", schema::find("verdict_frame_rate"));
  }
  {
    std::vector<std::string> problem, unit, method;
    std::vector<double> hz, target, err, cost, share;
    std::vector<std::int64_t> substeps;
    for (const auto& a : v.frame_answers) {
      problem.push_back(a.problem);
      unit.push_back(a.unit);
      hz.push_back(a.hz);
      target.push_back(a.target);
      method.push_back(a.method);
      substeps.push_back(a.substeps);
      err.push_back(a.err_pos_max);
      cost.push_back(a.cost_per_frame);
      share.push_back(a.frame_share);
    }
    h5::table t;
    t.add("problem", problem);
    t.add("unit", unit);
    t.add("hz", hz);
    t.add("target", target);
    t.add("method", method);
    t.add("substeps", substeps);
    t.add("err_pos_max", err);
    t.add("cost_per_frame", cost);
    t.add("frame_share", share);
    t.write(g, "frame_answer", schema::find("verdict_frame_answer"));
  }
}

void write_frame_rates(H5::Group& root, const study& s) {
  using h5::attr;
  const auto& studies = s.results.get<std::vector<frame_rate_study>>();
  if (studies.empty()) return;
  H5::Group fr = root.createGroup("frame_rates");
  const bool timed = s.timed.has_value();
  for (const auto& fs : studies) {
    H5::Group pg = fr.createGroup(fs.problem);
    attr(pg, "horizon", fs.horizon);
    attr(pg, "position_unit", fs.unit);
    std::vector<std::string> method, note;
    std::vector<double> hz, dt, err, evals, cost;
    std::vector<std::int64_t> substeps, steps;
    std::vector<std::int8_t> completed, diverged;
    const problem_study* ps = find_problem(s, fs.problem);
    for (const auto& r : fs.runs) {
      hz.push_back(r.hz);
      method.push_back(r.method);
      substeps.push_back(r.substeps);
      dt.push_back(r.row.param);
      completed.push_back(static_cast<std::int8_t>(r.row.metrics.completed()));
      diverged.push_back(static_cast<std::int8_t>(r.row.metrics.diverged));
      err.push_back(r.row.metrics.completed() ? r.row.metrics.err_pos_max : nan);
      steps.push_back(r.row.steps);
      evals.push_back(static_cast<double>(r.row.work.force_evals));
      cost.push_back(cost_per_frame(ps, fs, r, timed));
      note.push_back(r.row.metrics.note);
    }
    h5::table t;
    t.add("hz", hz);
    t.add("method", method);
    t.add("substeps", substeps);
    t.add("dt", dt);
    t.add("completed", completed);
    t.add("diverged", diverged);
    t.add("err_pos_max", err);
    t.add("steps", steps);
    t.add("force_evals", evals);
    t.add("cost_per_frame", cost);
    t.add("note", note);
    t.write(pg, "runs", schema::find("frame_rate_runs"));
  }
}

std::string format_verdict_text(const study& s) {
  const verdict_tables* v = s.results.find<verdict_tables>();
  return format_verdict_text(v ? *v : compute_verdict(s));
}

std::string format_verdict_text(const verdict_tables& v) {
  std::string out;
  const bool timed = v.cost_kind == "time_ns";
  // The equal-error table: problems down, every other target across.
  const std::vector<double> shown{1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12};
  std::vector<std::string> problems;
  for (const auto& e : v.equal_error)
    if (!contains(problems, e.problem)) problems.push_back(e.problem);
  {
    std::vector<column> cols{{"problem"}};
    for (double t : shown) cols.push_back({fmt::format("err <= {:g}", t)});
    table tb{cols, {}};
    for (const auto& p : problems) {
      std::vector<std::string> row{p};
      for (double t : shown) {
        std::string cell = "-";
        for (const auto& e : v.equal_error) {
          if (e.problem != p || e.target != t) continue;
          if (e.ours.found()) {
            cell = e.ours.method;
            if (std::isfinite(e.ratio))
              cell += fmt::format(" {:.2g}x{}", e.ratio,
                                  e.verdict == "ahead"     ? "+"
                                  : e.verdict == "behind"  ? "-"
                                  : e.verdict == "bounded" ? "?"
                                                           : "~");
          } else if (e.peer.found()) {
            cell = "(" + e.peer.method + ")";
          }
        }
        row.push_back(cell);
      }
      tb.add(row);
    }
    out += fmt::format(
        "Fastest of ours at equal error (err_pos_max in the problem's unit, m or rad), and its {} over the fastest "
        "library peer's: + ahead, - behind, ~ within the {}, ? undecided (the cheaper side's cost only bounded: "
        "its ladder does not bracket the target); (peer) when none of ours reaches it.\n",
        timed ? "time" : "force evaluations",
        timed ? "timing noise (the larger of 15 %, 25 % from a single repetition, and 3x the repetitions' spread)"
              : "interpolation's rounding");
    out += render_text(tb);
  }
  // The frame-rate table at 60 Hz.
  {
    const std::vector<double> targets{1e-2, 1e-4, 1e-6};
    std::vector<column> cols{{"problem"}, {"stable at 1 step"}};
    for (double t : targets) cols.push_back({fmt::format("cheapest for {:g}", t)});
    table tb{cols, {}};
    for (const auto& p : problems) {
      int stable = 0, total = 0;
      for (const auto& f : v.frame_rate)
        if (f.problem == p && f.hz == 60.0) {
          ++total;
          stable += f.stable;
        }
      if (total == 0) continue;
      std::vector<std::string> row{p, fmt::format("{} of {}", stable, total)};
      for (double t : targets) {
        std::string cell = "none <= x64";
        for (const auto& a : v.frame_answers)
          if (a.problem == p && a.hz == 60.0 && a.target == t && !a.method.empty())
            cell = with_substeps(a.method, a.substeps) + " " + cost_text(v.cost_kind, a.cost_per_frame);
        row.push_back(cell);
      }
      tb.add(row);
    }
    out += fmt::format(
        "\nAt {} (a frame of 16.7 ms): our fixed-step methods stable at one step a frame, and the cheapest method "
        "x substeps a frame whose err_pos_max meets each target, with its {} per frame "
        "(stepbench advise --problem P --hz HZ --tol X for other rates and targets).\n",
        hz_text(60), timed ? "measured time" : "force evaluations");
    out += render_text(tb);
  }
  out += "\nFindings:\n";
  for (const auto& f : v.findings) out += "  - " + f + "\n";
  return out;
}

verdict_agreement compare_verdicts(const verdict_tables& base, const verdict_tables& next) {
  verdict_agreement out;
  const auto decided = [](const std::string& v) { return v == "ahead" || v == "behind"; };
  for (const auto& b : base.equal_error)
    for (const auto& n : next.equal_error) {
      if (b.problem != n.problem || b.target != n.target) continue;
      if (decided(b.verdict) && decided(n.verdict)) {
        ++out.both_decided;
        if (b.verdict == n.verdict)
          ++out.agree;
        else
          out.flips.push_back(fmt::format("{} at {:g} {}: {} ({:.3g}x {}) -> {} ({:.3g}x {})", b.problem, b.target,
                                          b.unit, b.verdict, b.ratio, b.ours.method, n.verdict, n.ratio,
                                          n.ours.method));
      } else if (decided(b.verdict) != decided(n.verdict) && b.verdict != "ours only" && n.verdict != "ours only" &&
                 b.verdict != "peers only" && n.verdict != "peers only") {
        ++out.decided_in_one;
      }
    }
  return out;
}

std::string format_verdict_agreement(const verdict_agreement& a) {
  std::string out = fmt::format(
      "Equal-error verdicts (fastest of ours against the fastest peer): {} of {} problem-and-target pairs decided "
      "(ahead or behind beyond the timing noise) in both files agree; {} decided in one file are within the noise in "
      "the "
      "other.\n",
      a.agree, a.both_decided, a.decided_in_one);
  for (const auto& f : a.flips) out += "  flips: " + f + "\n";
  return out;
}

verdict_tables read_verdict(const std::string& path) {
  try {
    if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
    const H5::H5File file(path, H5F_ACC_RDONLY);
    return read_verdict(file);
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read the verdict of study file '{}': {}", path, e.getDetailMsg()));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("cannot read the verdict of study file '{}': {}", path, e.what()));
  }
}

verdict_tables read_verdict(const H5::Group& root) {
  verdict_tables v;
  {
    if (!h5::is_group(root, "verdict"))
      throw std::runtime_error("it has no /verdict (written before format_version 4: run the study again)");
    const H5::Group g = root.openGroup("verdict");
    v.cost_kind = h5::string_attr(g, "cost_kind");
    const std::string findings = h5::string_attr(g, "findings");
    for (std::size_t a = 0; a < findings.size();) {
      const auto b = std::min(findings.find('\n', a), findings.size());
      v.findings.push_back(findings.substr(a, b - a));
      a = b + 1;
    }
    {
      const auto t = h5::read_table(g.openDataSet("equal_error"));
      const auto &problem = t.strings("problem"), &unit = t.strings("unit"), &om = t.strings("ours_method"),
                 &ok = t.strings("ours_kind"), &pm = t.strings("peer_method"), &pk = t.strings("peer_kind"),
                 &verdict = t.strings("verdict"), &cost_kind = t.strings("cost_kind");
      const auto target = t.doubles("target"), op = t.doubles("ours_param"), oc = t.doubles("ours_cost"),
                 ol = t.doubles("ours_cost_lo"), oh = t.doubles("ours_cost_hi"), pp = t.doubles("peer_param"),
                 pc = t.doubles("peer_cost"), pl = t.doubles("peer_cost_lo"), ph = t.doubles("peer_cost_hi"),
                 ratio = t.doubles("ratio"), best = t.doubles("best_error"), oi = t.doubles("ours_interpolated"),
                 pi = t.doubles("peer_interpolated");
      for (std::size_t i = 0; i < t.rows(); ++i)
        v.equal_error.push_back({problem[i],
                                 unit[i],
                                 target[i],
                                 {om[i], ok[i], op[i], oc[i], ol[i], oh[i], oi[i] != 0},
                                 {pm[i], pk[i], pp[i], pc[i], pl[i], ph[i], pi[i] != 0},
                                 ratio[i],
                                 cost_kind[i],
                                 verdict[i],
                                 best[i]});
    }
    {
      const auto t = h5::read_table(g.openDataSet("frame_rate"));
      const auto &problem = t.strings("problem"), &unit = t.strings("unit"), &method = t.strings("method"),
                 &note = t.strings("note");
      const auto hz = t.doubles("hz"), stable = t.doubles("stable"), err = t.doubles("err_pos_max");
      for (std::size_t i = 0; i < t.rows(); ++i)
        v.frame_rate.push_back({problem[i], unit[i], method[i], note[i], hz[i], stable[i] != 0, err[i]});
    }
    {
      const auto t = h5::read_table(g.openDataSet("frame_answer"));
      const auto &problem = t.strings("problem"), &unit = t.strings("unit"), &method = t.strings("method");
      const auto hz = t.doubles("hz"), target = t.doubles("target"), substeps = t.doubles("substeps"),
                 err = t.doubles("err_pos_max"), cost = t.doubles("cost_per_frame"), share = t.doubles("frame_share");
      for (std::size_t i = 0; i < t.rows(); ++i)
        v.frame_answers.push_back({problem[i], unit[i], method[i], hz[i], target[i], static_cast<int>(substeps[i]),
                                   err[i], cost[i], share[i]});
    }
  }
  return v;
}

}  // namespace stepbench

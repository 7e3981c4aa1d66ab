#include "judge/verdict.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "core/contains.hpp"
#include "core/number.hpp"
#include "core/work_precision.hpp"
#include "judge/loop.hpp"
#include "judge/substeps.hpp"
#include "registry/registry.hpp"

namespace stepbench {

double cost_per_frame(const problem_study* ps, const frame_rate_study& fs, const frame_rate_run& r, bool timed) {
  const double frames = fs.horizon * r.hz;
  if (!timed) return static_cast<double>(r.row.work.force_evals) / frames;
  const double ns = ps ? measured_step_cost_ns(*ps, r.method) : nan;
  return std::isfinite(ns) && ns > 0.0 ? ns * r.substeps : nan;
}

std::vector<frame_option> frame_options(const study& s, const frame_rate_study& fs) {
  const problem_study* ps = s.find(fs.problem);
  std::vector<frame_option> out;
  for (const auto& r : fs.runs) {
    const auto& m = r.row.metrics;
    out.push_back({r.method, m.note, r.hz, r.substeps, r.row.param, m.completed(), m.diverged,
                   m.completed() ? m.err_pos_max : nan, r.row.steps, static_cast<double>(r.row.work.force_evals),
                   cost_per_frame(ps, fs, r, s.timed.has_value())});
  }
  return out;
}

namespace {

// A ratio in two digits, never in exponent form: 1.5, 12, 120 (not 1.2e+02).
std::string ratio_text(double r) { return r >= 100 ? fmt::format("{:.0f}", r) : fmt::format("{:.2g}", r); }

cost_at_error cost_of(const std::vector<wp_method>& methods, const wp_pick* p) {
  if (!p) return {};
  const auto& m = methods[p->method];
  return {m.name,        std::string(to_string(m.kind)), p->param, p->cost, p->cost_lo, p->cost_hi, p->interpolated,
          p->force_evals};
}

// `mine` against `other` at equal error, "ahead" when mine is cheaper; the one-sided
// outcomes are named by the caller (ours against a peer, a plugin's against either).
std::string verdict_of(const cost_at_error& mine, const cost_at_error& other, bool timed,
                       const char* mine_only = "ours only", const char* other_only = "peers only") {
  if (!mine.found() && !other.found()) return "not reached";
  if (!other.found()) return mine_only;
  if (!mine.found()) return other_only;
  const std::string v = compare_at_equal_error({mine.cost, mine.cost_lo, mine.cost_hi},
                                               {other.cost, other.cost_lo, other.cost_hi}, timed);
  // The side found dearer charged only an upper bound proves nothing: its true cost may be lower.
  if ((v == "ahead" && !other.interpolated) || (v == "behind" && !mine.interpolated)) return "bounded";
  return v;
}

}  // namespace

// The findings: one sentence each, from the verdicts just computed and the studies'.
std::vector<std::string> findings_of(const verdict_tables& v, const finding_inputs& in) {
  std::vector<std::string> out;
  const bool timed = v.cost_kind == "time_ns";
  // Equal error.
  {
    std::map<std::string, int> n;  // by verdict
    const equal_error_verdict* best_win = nullptr;
    const equal_error_verdict* worst_loss = nullptr;
    for (const auto& e : v.equal_error) {
      ++n[e.verdict];
      if (e.verdict == "ahead" && (!best_win || e.ratio < best_win->ratio)) best_win = &e;
      if (e.verdict == "behind" && (!worst_loss || e.ratio > worst_loss->ratio)) worst_loss = &e;
    }
    std::string line = fmt::format(
        "At equal error ({}, interpolated on each method's measured curve), the fastest of ours against the "
        "fastest library peer: ahead on {}, behind on {}, within the {} on {}, undecided on {} (the side found "
        "dearer only bounded: its ladder does not bracket the target) of the {} problem-and-target pairs both "
        "reach; only ours reach {}, only a peer {}.",
        timed ? "measured time" : "force evaluations", n["ahead"], n["behind"], timed ? "timing noise" : "rounding",
        n["within spread"], n["bounded"], n["ahead"] + n["behind"] + n["within spread"] + n["bounded"], n["ours only"],
        n["peers only"]);
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
  // The plugins' methods at equal error, against ours and against the peers.
  if (!v.plugin_equal_error.empty()) {
    std::map<std::string, int> vs_ours, vs_peer;
    std::vector<std::string> names;
    for (const auto& e : v.plugin_equal_error) {
      ++vs_ours[e.verdict_ours];
      ++vs_peer[e.verdict_peer];
      if (e.plugin.found() && !contains(names, e.plugin.method)) names.push_back(e.plugin.method);
    }
    const auto counts = [&](std::map<std::string, int>& n) {
      return fmt::format("ahead on {}, behind on {}, within the {} on {}, undecided on {} of the {} pairs both reach",
                         n["ahead"], n["behind"], timed ? "timing noise" : "rounding", n["within spread"], n["bounded"],
                         n["ahead"] + n["behind"] + n["within spread"] + n["bounded"]);
    };
    out.push_back(fmt::format(
        "The plugins' fastest method at equal error ({}) against the fastest of ours: {}; against the fastest "
        "library peer: {}; a plugin method reaches {} of the {} problem-and-target pairs.",
        names.empty() ? std::string("none reaches a target") : fmt::format("{}", fmt::join(names, ", ")),
        counts(vs_ours), counts(vs_peer),
        std::count_if(v.plugin_equal_error.begin(), v.plugin_equal_error.end(),
                      [](const plugin_at_error& e) { return e.plugin.found(); }),
        v.plugin_equal_error.size()));
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
    else {
      const bool better = sv.explicit_error <= sv.implicit_error;
      line += fmt::format(
          "{} semi_implicit_euler substep{} cost as much as one implicit_euler step and are {}x {} accurate", n,
          n == 1 ? "" : "s",
          ratio_text(better ? sv.implicit_error / sv.explicit_error : sv.explicit_error / sv.implicit_error),
          better ? "more" : "less");
    }
    if (sv.substeps_to_match > 0) line += fmt::format("; {} substeps match its error", sv.substeps_to_match);
    out.push_back(line + ".");
  }
  // Declared orders that do not hold.
  std::string broken;
  for (const auto& [m, ps] : in.broken_orders)
    broken += fmt::format("{}{} on {} problem{}", broken.empty() ? "" : ", ", m, ps.size(), ps.size() == 1 ? "" : "s");
  out.push_back(
      broken.empty()
          ? "Every library method's observed order matches its declared order where it can be fitted."
          : fmt::format("Library methods whose observed order differs from the order they declare: {}.", broken));
  // xpbd's stability and energy over its dt ladder (at a 60 Hz frame, the substep
  // ladder): the claim that rigid links stay stable at every substep count, and
  // XPBD's projection only removing energy, as the study's own runs show them. The energy
  // is the run's at its end (energy_drift), not its largest excursion: the text says so.
  std::vector<std::string> ladder_methods;
  for (const auto& l : in.small_steps_ladders)
    if (!contains(ladder_methods, l.method)) ladder_methods.push_back(l.method);
  for (const auto& method : ladder_methods) {
    std::string parts;
    for (const auto& [m, problem, runs] : in.small_steps_ladders) {
      if (m != method) continue;
      int ran = 0, completed = 0, diverged = 0, failed = 0;
      double dt_max = 0.0, dt_min = std::numeric_limits<double>::infinity();
      const ladder_run *coarsest = nullptr, *finest = nullptr;  // of the completed runs
      // The highest signed drift, not the largest in size: whether any run gained energy.
      double highest_drift = -std::numeric_limits<double>::infinity(), worst_constraint = nan;
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
        highest_drift = std::fmax(highest_drift, r.energy_drift);  // fmax drops a NaN
        worst_constraint = std::fmax(worst_constraint, r.constraint_violation);
      }
      if (ran == 0) continue;  // every rung over the work budget: nothing to say of it
      std::string part = fmt::format("{} completed {} of the {} dt it ran ({} to {})", problem, completed, ran,
                                     format_time_ns(dt_max * 1e9), format_time_ns(dt_min * 1e9));
      if (diverged > 0) part += fmt::format(", diverged at {}", diverged);
      if (failed > 0) part += fmt::format(", failed at {}", failed);
      // A merged file may lack a drift (NaN): say only the numbers the runs have.
      if (coarsest && std::isfinite(coarsest->energy_drift) && std::isfinite(finest->energy_drift))
        part += fmt::format(", final energy drift {:.2g} at {} and {:.2g} at {} (highest {:.2g})",
                            coarsest->energy_drift, format_time_ns(coarsest->dt * 1e9), finest->energy_drift,
                            format_time_ns(finest->dt * 1e9), highest_drift);
      if (std::isfinite(worst_constraint)) part += fmt::format(", |C|/L within {:.2g}", worst_constraint);
      parts += (parts.empty() ? "" : "; ") + part;
    }
    if (!parts.empty())
      out.push_back(fmt::format(
          "{} over its dt ladder (final energy drift: the energy at the run's end against the truth's, of the "
          "problem's energy scale, at the coarsest and the finest completed dt and the highest over the completed, "
          "the most energy gained or the least lost; "
          "|C|/L: the largest relative length error of a rigid link, the stretch of a spring, over the run): {}.",
          method, parts));
  }
  // Stability at 60 Hz, one step a frame.
  std::map<std::string, std::vector<std::string>> unstable;  // problem -> methods
  for (const auto& f : v.frame_rate)
    if (f.hz == 60.0 && !f.stable) unstable[f.problem].push_back(f.method);
  if (!unstable.empty()) {
    std::string parts;
    for (const auto& [p, ms] : unstable)
      parts += fmt::format("{}{}: {}", parts.empty() ? "" : "; ", p, fmt::join(ms, ", "));
    out.push_back(fmt::format("At 60 Hz, one step a frame, these diverge or fail: {}.", parts));
  } else if (std::any_of(v.frame_rate.begin(), v.frame_rate.end(), [](const auto& f) { return f.hz == 60.0; })) {
    out.push_back("At 60 Hz, one step a frame, every fixed-step method of ours stays stable on every problem.");
  }
  return out;
}

bool is_first_order_pair(const substep_verdict& sv) {
  const method_info* im = registered_method(sv.implicit_method);
  const method_info* em = registered_method(sv.explicit_method);
  return im && em && im->declared_order == 1.0 && im->traits.needs_jacobian && !im->traits.symplectic &&
         em->declared_order == 1.0 && em->traits.symplectic && !em->traits.needs_jacobian;
}

finding_inputs finding_inputs_of(const study& s) {
  finding_inputs in;
  for (const auto& st : s.results.get<std::vector<substep_study>>())
    for (const auto& sv : substep_verdicts(st, s.timed.has_value()))
      if (is_first_order_pair(sv)) in.substeps.push_back({st.problem, st.frame_dt, sv});
  for (const auto& ps : s.problems)
    for (const auto& ms : ps.methods)
      if (ms.info.origin == method_origin::peer && ms.declared_order_holds == 0)
        in.broken_orders[ms.info.name].insert(ps.name);
  for (const auto& ps : s.problems)
    for (const auto& ms : ps.methods) {
      if (!ms.info.traits.small_steps) continue;
      ladder_finding f{ms.info.name, ps.name, {}};
      for (const auto& r : ms.rows) {
        const auto& m = r.metrics;
        f.runs.push_back({r.param, m.diverged, m.failed, m.skipped, m.energy_drift, m.constraint_violation_max});
      }
      in.small_steps_ladders.push_back(std::move(f));
    }
  return in;
}

verdict_tables compute_verdict(const study& s) {
  verdict_tables v;
  const bool timed = s.timed.has_value();
  v.cost_kind = timed ? "time_ns" : "force_evals";
  for (const auto& ps : s.problems) {
    const auto methods = work_precision_input(ps, verdict_metric);
    const std::string unit(ps.unit);
    double best_error = std::numeric_limits<double>::infinity();
    for (const auto& m : methods)
      if (m.origin != method_origin::baseline)
        for (const auto& r : m.rows)
          if (r.completed && std::isfinite(r.error)) best_error = std::min(best_error, r.error);
    const bool has_plugin = std::any_of(methods.begin(), methods.end(),
                                        [](const wp_method& m) { return m.origin == method_origin::plugin; });
    for (double target : verdict_targets()) {
      const auto r = cheapest(methods, target, timed, verdict_metric, unit,
                              timed ? wp_candidates::timed_methods : wp_candidates::every_method);
      const wp_pick *ours = nullptr, *peer = nullptr, *plugin = nullptr;
      for (const auto& p : r.ranked) {
        if (methods[p.method].origin == method_origin::ours && !ours) ours = &p;
        if (methods[p.method].origin == method_origin::peer && !peer) peer = &p;
        if (methods[p.method].origin == method_origin::plugin && !plugin) plugin = &p;
      }
      const cost_at_error o = cost_of(methods, ours), q = cost_of(methods, peer);
      const bool by_time = r.cost == "time_ns";
      auto& e = v.equal_error.emplace_back(
          equal_error_verdict{ps.name, unit, target, o, q, ours && peer ? ours->cost / peer->cost : nan, r.cost,
                              verdict_of(o, q, by_time), std::isfinite(best_error) ? best_error : nan});
      if (ours && peer) {
        e.noise_factor = 1.0 + equal_error_threshold(band_of(*ours), band_of(*peer), by_time);
        e.evals_ratio = ours->force_evals / peer->force_evals;
        if (by_time) e.per_eval_ratio = e.ratio / e.evals_ratio;
      }
      if (has_plugin) {
        const cost_at_error y = cost_of(methods, plugin);
        v.plugin_equal_error.push_back({ps.name, unit, target, y, plugin && ours ? plugin->cost / ours->cost : nan,
                                        plugin && peer ? plugin->cost / peer->cost : nan, r.cost,
                                        verdict_of(y, o, by_time, "plugin only", "others only"),
                                        verdict_of(y, q, by_time, "plugin only", "others only")});
      }
    }
  }
  for (const auto& fs : s.results.get<std::vector<frame_rate_study>>()) {
    const problem_study* ps = s.find(fs.problem);
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

}  // namespace stepbench

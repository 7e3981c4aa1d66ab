#include "judge/advise.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/work_precision.hpp"
#include "render/table_render.hpp"

namespace stepbench {
namespace {

// The cost at equal error, with its repetition spread when timed.
std::string cost_text(const std::string& cost, const wp_pick& p) {
  if (cost == "force_evals") return fmt::format("{:.0f} force evals", p.force_evals);
  if (p.cost_lo < p.cost_hi)
    return fmt::format("{} ({} .. {})", format_time_ns(p.time_ns), format_time_ns(p.cost_lo),
                       format_time_ns(p.cost_hi));
  return format_time_ns(p.time_ns);
}

// "dt 0.0031 s" for an interpolated point; "dt 0.0039 s (run)" for a measured row.
std::string where(const wp_method& m, const wp_pick& p) {
  return p.interpolated ? format_param(m.kind, p.param) + " (interpolated)" : format_param(m.kind, p.param);
}

std::string label(const wp_method& m) {
  return m.origin == method_origin::peer       ? m.name + " (peer)"
         : m.origin == method_origin::baseline ? m.name + " (baseline, for scale)"
                                               : m.name;
}

}  // namespace

std::string format_advice(const advice& a, std::size_t runners_up) {
  const auto& r = a.result;
  std::string out;
  const std::string cost_name = r.cost == "time_ns" ? "measured time per run (median)"
                                : a.timed           ? "force evaluations (some qualifying rows are not timed)"
                                                    : "force evaluations (the study has no timings)";
  // The stability margin: how far the chosen row is from the rows that blew up.
  auto margin = [&](const wp_pick& p) {
    const auto kind = a.methods[p.method].kind;
    if (!p.largest_diverged) return std::string("never diverged in the study");
    if (p.diverged_rows == 1) return fmt::format("diverged at {}", format_param(kind, *p.largest_diverged));
    return fmt::format("diverged at {} rows: {} .. {}", p.diverged_rows, format_param(kind, *p.smallest_diverged),
                       format_param(kind, *p.largest_diverged));
  };
  out += fmt::format("{}: {} <= {:g} {}; cost = {} at equal error, interpolated between the measured rows\n", a.problem,
                     a.metric, a.tol, a.unit, cost_name);
  const auto answer = r.answer(a.methods);
  if (!answer) {
    out += fmt::format("no method in the study meets {} <= {:g} {} on {}", a.metric, a.tol, a.unit, a.problem);
    if (r.best_achieved) {
      const auto& m = a.methods[r.best_achieved->method];
      out += fmt::format("; the best achieved is {} {:.3g} {} by {} at {}", a.metric, r.best_achieved->error, a.unit,
                         m.name, format_param(m.kind, r.best_achieved->param));
    }
    out += "\n";
  } else {
    const auto& m = a.methods[answer->method];
    out += fmt::format("use {} at {}: {}, {} {:.3g} {}; {}\n", label(m), where(m, *answer), cost_text(r.cost, *answer),
                       a.metric, answer->error, a.unit, margin(*answer));
  }
  if (!a.scene.empty()) out += fmt::format("scene: {}\n", a.scene);
  std::vector<const wp_pick*> others;
  for (const auto& p : r.ranked)
    if (!answer || p.method != answer->method) others.push_back(&p);
  if (!others.empty()) {
    table t{{right_column("rank"), "method", "dt or tolerance", right_column("cost"), right_column(a.metric, a.unit),
             "stability margin"},
            {}};
    for (std::size_t i = 0; i < others.size() && i < runners_up; ++i) {
      const auto& m = a.methods[others[i]->method];
      t.add({fmt::format("{}.", i + 2), label(m), where(m, *others[i]), cost_text(r.cost, *others[i]),
             fmt::format("{:.3g}", others[i]->error), margin(*others[i])});
    }
    out += (answer ? "runners-up:\n" : "for scale:\n") + render_text(t);
    if (others.size() > runners_up)
      out += fmt::format("  ... and {} more that also meet the tolerance\n", others.size() - runners_up);
  }
  if (!r.excluded.empty()) {
    table t{{"method", "reason"}, {}};
    for (const auto& e : r.excluded) t.add({label(a.methods[e.method]), e.reason});
    out += "excluded:\n" + render_text(t);
  }
  return out;
}

std::string format_frame_advice(const frame_advice& f) {
  const bool timed = f.cost_kind == "time_ns";
  auto cost = [&](double c) {
    if (!std::isfinite(c)) return std::string("n/a");
    return timed ? fmt::format("{} ({:.2g}% of the frame)", format_time_ns(c), 100.0 * c / (1e9 / f.hz))
                 : fmt::format("{:.3g} force evals", c);
  };
  std::string out;
  const double frame_ms = 1e3 / f.hz;
  if (f.ranked.empty())
    out += fmt::format(
        "{} at {:g} Hz: no fixed-step method of ours meets err_pos_max <= {:g} {} within the substep "
        "counts run\n",
        f.problem, f.hz, f.tol, f.unit);
  else
    out += fmt::format(
        "{} at {:g} Hz: use {} with {} substep{} a frame (dt {:.3g} ms): err_pos_max {:.3g} {}, {} a "
        "frame\n",
        f.problem, f.hz, f.ranked.front().method, f.ranked.front().substeps, f.ranked.front().substeps == 1 ? "" : "s",
        frame_ms / f.ranked.front().substeps, f.ranked.front().err_pos_max, f.unit,
        cost(f.ranked.front().cost_per_frame));
  out += fmt::format(
      "measured over {:.3g} s of whole frames against the truth at the frame ends; cost a frame = {}\n", f.horizon,
      timed ? "the benchmark's median ns per step x steps a frame" : "force evaluations (untimed study)");
  if (!f.scene.empty()) out += fmt::format("scene: {}\n", f.scene);
  if (f.ranked.size() > 1) {
    table t{{"method", right_column("substeps"), right_column("err_pos_max", f.unit), right_column("cost a frame")},
            {}};
    for (std::size_t i = 1; i < f.ranked.size(); ++i)
      t.add({f.ranked[i].method, fmt::format("{}", f.ranked[i].substeps),
             fmt::format("{:.3g}", f.ranked[i].err_pos_max), cost(f.ranked[i].cost_per_frame)});
    out += "also meeting it:\n" + render_text(t);
  }
  if (!f.not_meeting.empty()) {
    out += "not ranked:\n";
    for (const auto& n : f.not_meeting) out += "  " + n + "\n";
  }
  table t{{"method", "one step a frame", right_column("err_pos_max", f.unit)}, {}};
  for (const auto& o : f.one_step)
    t.add({o.method, o.completed ? "stable" : (o.diverged ? "diverges" : "fails: " + o.note),
           o.completed ? fmt::format("{:.3g}", o.err_pos_max) : "-"});
  out += fmt::format("at one step a frame (dt {:.3g} ms):\n", frame_ms) + render_text(t);
  return out;
}

}  // namespace stepbench

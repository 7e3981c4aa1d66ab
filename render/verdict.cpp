#include "render/verdict.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/contains.hpp"
#include "judge/verdict.hpp"
#include "render/table_render.hpp"
#include "store/study_file.hpp"

namespace stepbench {
namespace {

std::string cost_text(const std::string& kind, double c) {
  if (!std::isfinite(c)) return "-";
  return kind == "time_ns" ? format_time_ns(c) : fmt::format("{:.3g} evals", c);
}

// A ratio at equal error with its verdict's mark (format_verdict_text's legend).
std::string marked_ratio(double ratio, const std::string& verdict) {
  return fmt::format("{:.2g}x{}", ratio,
                     verdict == "ahead"     ? "+"
                     : verdict == "behind"  ? "-"
                     : verdict == "bounded" ? "?"
                                            : "~");
}

}  // namespace

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
  // A table of problems down and the shown targets across, a cell from each row of `rows`
  // at its (problem, target): "-" where none.
  const auto by_target = [&](const auto& rows, const auto& cell_of) {
    std::vector<column> cols{{"problem"}};
    for (double t : shown) cols.push_back({fmt::format("err <= {:g}", t)});
    table tb{cols, {}};
    for (const auto& p : problems) {
      std::vector<std::string> row{p};
      for (double t : shown) {
        std::string cell = "-";
        for (const auto& e : rows)
          if (e.problem == p && e.target == t) cell = cell_of(e);
        row.push_back(cell);
      }
      tb.add(row);
    }
    return render_text(tb);
  };
  out += fmt::format(
      "Fastest of ours at equal error (err_pos_max in the problem's unit, m or rad), and its {} over the fastest "
      "library peer's: + ahead, - behind, ~ within the {}, ? undecided (the dearer side's cost only bounded: "
      "its ladder does not bracket the target); (peer) when none of ours reaches it.\n",
      timed ? "time" : "force evaluations",
      timed ? "timing noise (the larger of 15 %, 25 % from a single repetition, and 3x the repetitions' spread)"
            : "interpolation's rounding");
  out += by_target(v.equal_error, [](const equal_error_verdict& e) -> std::string {
    if (e.ours.found())
      return e.ours.method + (std::isfinite(e.ratio) ? " " + marked_ratio(e.ratio, e.verdict) : std::string());
    return e.peer.found() ? "(" + e.peer.method + ")" : "-";
  });
  // The plugins' fastest method at the same targets, against both sides.
  if (!v.plugin_equal_error.empty()) {
    out += fmt::format(
        "\nFastest plugin method at equal error, and its {} over the fastest of ours's / over the fastest library "
        "peer's (marks as above, from the plugin's side: + the plugin's is cheaper); - where none reaches it.\n",
        timed ? "time" : "force evaluations");
    out += by_target(v.plugin_equal_error, [](const plugin_at_error& e) -> std::string {
      if (!e.plugin.found()) return "-";
      const auto against = [](double r, const std::string& verdict) {
        return std::isfinite(r) ? marked_ratio(r, verdict) : std::string("-");
      };
      return e.plugin.method + " " + against(e.vs_ours, e.verdict_ours) + " / " + against(e.vs_peer, e.verdict_peer);
    });
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
            cell = (a.substeps == 1 ? a.method : fmt::format("{} x{}", a.method, a.substeps)) + " " +
                   cost_text(v.cost_kind, a.cost_per_frame);
        row.push_back(cell);
      }
      tb.add(row);
    }
    out += fmt::format(
        "\nAt 60 Hz (a frame of 16.7 ms): our fixed-step methods stable at one step a frame, and the cheapest method "
        "x substeps a frame whose err_pos_max meets each target, with its {} per frame "
        "(stepbench advise --problem P --hz HZ --tol X for other rates and targets).\n",
        timed ? "measured time" : "force evaluations");
    out += render_text(tb);
  }
  out += "\nFindings:\n";
  for (const auto& f : v.findings) out += "  - " + f + "\n";
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

}  // namespace stepbench

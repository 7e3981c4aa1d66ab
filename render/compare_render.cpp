#include "render/compare_render.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/work_precision.hpp"
#include "render/table_render.hpp"

namespace stepbench {
namespace {

std::string value_text(const compare_value& v) {
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  const double d = std::get<double>(v);
  return std::isnan(d) ? "NaN" : fmt::format("{:.3g}", d);
}

std::string ratio_text(double r) { return std::isnan(r) ? "-" : std::isinf(r) ? "inf" : fmt::format("{:.3g}", r); }

std::string param_text(const std::string& name, double param) {
  if (name.empty()) return "-";
  return format_param(name == "tolerance" ? method_kind::adaptive : method_kind::fixed_step, param);
}

table changes_table(const comparison& c, change_kind k) {
  table t{{"problem", "method", "dt or tolerance", "what", right_column("old"), right_column("new"),
           right_column("ratio"), "note"},
          {}};
  for (const auto& x : c.changes)
    if (x.kind == k)
      t.add({x.problem, x.method.empty() ? "-" : x.method, param_text(x.param_name, x.param), x.what,
             value_text(x.old_value), value_text(x.new_value), ratio_text(x.ratio), x.note});
  // The note column only when some finding has one.
  if (std::all_of(t.rows.begin(), t.rows.end(), [](const auto& r) { return r.back().empty(); }))
    t.drop_column(t.columns.size() - 1);
  return t;
}

table presence_table(const std::vector<presence>& items) {
  table t{{"problem", "method", "what", "detail"}, {}};
  for (const auto& p : items) t.add({p.problem, p.method.empty() ? "-" : p.method, p.what, p.detail});
  return t;
}

table differences_table(const comparison& c) {
  table t{{"what", "BASE", "NEW"}, {}};
  for (const auto& d : c.differences) t.add({d.what, d.old_value, d.new_value});
  return t;
}

std::string side_text(const timing& s) {
  return s.repetitions >= 2 ? fmt::format("{} ({}..{}, {} reps)", format_time_ns(s.time_ns),
                                          format_time_ns(s.time_ns_min), format_time_ns(s.time_ns_max), s.repetitions)
                            : fmt::format("{} (1 rep)", format_time_ns(s.time_ns));
}

table timing_flagged_table(const comparison& c) {
  table t{{"problem", "method", "dt or tolerance", "old median", "new median", right_column("new/old"),
           right_column("threshold"), "flag"},
          {}};
  for (const auto& r : c.timing)
    if (r.flag != 0)
      t.add({r.problem, r.method, param_text(r.param_name, r.param), side_text(r.old_time), side_text(r.new_time),
             fmt::format("{:.3f}", r.ratio), fmt::format("+{:.0f} %", 100 * r.threshold),
             r.flag > 0 ? "slower" : "faster"});
  return t;
}

table timing_summary_table(const comparison& c) {
  table t{{"method", right_column("problems"), right_column("rows"), right_column("geomean new/old"),
           right_column("min"), right_column("max"), right_column("slower"), right_column("faster")},
          {}};
  for (const auto& s : c.timing_summaries)
    t.add({s.method, std::to_string(s.problems), std::to_string(s.rows), fmt::format("{:.3f}", s.geomean),
           fmt::format("{:.3f}", s.min_ratio), fmt::format("{:.3f}", s.max_ratio), std::to_string(s.slower),
           std::to_string(s.faster)});
  return t;
}

std::string file_line(const std::map<std::string, std::string>& meta, bool timed) {
  const auto get = [&](const char* k) {
    const auto it = meta.find(k);
    return it == meta.end() ? std::string("?") : it->second;
  };
  return fmt::format("created {}, stepbench {} ({}), {} {}, {}", get("created_utc"), get("version"), get("git_commit"),
                     get("compiler"), get("build_type"),
                     timed ? fmt::format("timed ({})", get("benchmark_mode")) : std::string("untimed"));
}

std::string verdict(const comparison& c) { return c.exit_status() == 0 ? "no regression" : "REGRESSION"; }

std::string timing_heading(const comparison& c) {
  const auto single = std::count_if(c.timing.begin(), c.timing.end(), [](const timing_row& r) {
    return r.old_time.repetitions < 2 || r.new_time.repetitions < 2;
  });
  return fmt::format(
      "new/old of the median time_ns, {} rows timed in both; {} slower, {} faster beyond the noise{}.{}{}",
      c.timing.size(), c.slower(), c.faster(),
      c.options.gate_timing ? " (gating: --gate-timing)" : " (informs only; --gate-timing to gate)",
      c.timing_note.empty() ? "" : fmt::format(" Note: {}.", c.timing_note),
      single == 0 ? std::string()
                  : fmt::format(" {} of them have a single repetition on a side: no spread to measure, "
                                "so their threshold is the {:g} % fallback.",
                                single, 100 * timing_single_run_floor));
}

// The four sections both forms share: regressions, improvements, what only NEW has and
// what only BASE has, each a title with its count and a table (or "none").
std::string findings(const comparison& c, table_format f) {
  const bool md = f == table_format::markdown;
  std::string out;
  const auto section = [&](const std::string& title, std::size_t n, const table& t, const std::string& note = "") {
    if (n == 0) {
      out += md ? fmt::format("\n### {}: none\n", title) : fmt::format("\n{}: none\n", title);
      return;
    }
    out += md ? fmt::format("\n### {} ({}){}\n\n", title, n, note) : fmt::format("\n{} ({}){}:\n", title, n, note);
    out += render(t, f);
  };
  const std::string flag = md ? "`--require-base`" : "--require-base";
  // With --require-base what only BASE has counts too, as the result line counts it.
  const std::size_t changed = c.count(change_kind::regression), gone = c.options.require_base ? c.removed.size() : 0;
  if (changed == 0 && gone > 0)
    out += fmt::format("{}Regressions ({}): the removed, below ({})\n", md ? "\n### " : "\n", gone, flag);
  else
    section("Regressions", changed + gone, changes_table(c, change_kind::regression),
            gone > 0 ? fmt::format(", {} of them removed, below ({})", gone, flag) : "");
  section("Improvements", c.count(change_kind::improvement), changes_table(c, change_kind::improvement));
  section("Added, only in NEW", c.added.size(), presence_table(c.added));
  section("Removed, only in BASE", c.removed.size(), presence_table(c.removed),
          c.options.require_base ? ", regressions (" + flag + ")" : ", listed, not compared");
  return out;
}

// The whole report. Markdown (a CI job summary) opens with the verdict and folds the
// thresholds and the per-method timing away; text keeps the order of reading.
std::string report(const comparison& c, table_format f) {
  const bool md = f == table_format::markdown;
  std::string out;
  if (md) {
    out = fmt::format("## stepbench compare: {}\n\n**{}** (exit {})\n\n", verdict(c), summary_line(c), c.exit_status());
    table files{{"", "file", "build"}, {}};
    files.add({"BASE", "`" + c.base_path + "`", file_line(c.base_meta, c.base_timed)});
    files.add({"NEW", "`" + c.new_path + "`", file_line(c.new_meta, c.new_timed)});
    out += render_markdown(files);
  } else {
    out = fmt::format("stepbench compare\n  BASE {}\n       {}\n  NEW  {}\n       {}\n", c.base_path,
                      file_line(c.base_meta, c.base_timed), c.new_path, file_line(c.new_meta, c.new_timed));
    out += fmt::format("\nResult: {} (exit {}): {}\n", verdict(c), c.exit_status(), summary_line(c));
  }
  if (c.differences.empty())
    out += "\nThe files agree in machine, build and settings.\n";
  else
    out += (md ? "\n### The files differ in\n\n" : "\nThe files differ in (results may differ for these reasons):\n") +
           render(differences_table(c), f);
  if (!md) {
    out += "\nThresholds:\n";
    for (const auto& line : describe_thresholds(c.options)) out += wrap(line, "  - ", "    ");
  }
  out += findings(c, f);
  if (!c.timing_compared) {
    out += md ? fmt::format("\n### Timing\n\nNot compared ({}).\n", c.timing_note)
              : fmt::format("\nTiming: not compared ({})\n", c.timing_note);
  } else {
    out += md ? fmt::format("\n### Timing\n\n{}\n\n", timing_heading(c)) : wrap(timing_heading(c), "\nTiming: ", "  ");
    if (c.slower() + c.faster() > 0) out += render(timing_flagged_table(c), f);
    const std::string title =
        "Timing per method (geometric mean of new/old over its rows timed in both, every problem)";
    if (!c.timing_summaries.empty())
      out += md ? "\n<details><summary>" + title + "</summary>\n\n" + render_markdown(timing_summary_table(c)) +
                      "\n</details>\n"
                : "\n" + title + ":\n" + render_text(timing_summary_table(c));
  }
  if (md) {
    out += "\n<details><summary>Thresholds</summary>\n\n";
    for (const auto& line : describe_thresholds(c.options)) out += "- " + line + "\n";
    out += "\n</details>\n";
  }
  return out;
}

}  // namespace

std::string summary_line(const comparison& c) {
  // With --require-base a removed case is a regression, and is counted as one here.
  const std::size_t gone = c.options.require_base ? c.removed.size() : 0;
  std::string s = fmt::format(
      "{}, {}, {} added, {} removed{}", plural(c.count(change_kind::regression) + gone, "regression", "regressions"),
      plural(c.count(change_kind::improvement), "improvement", "improvements"), c.added.size(), c.removed.size(),
      c.removed.empty() ? ""
      : gone > 0        ? " (regressions: --require-base)"
                        : " (not compared)");
  if (c.timing_compared)
    s += fmt::format("; timing: {} of {} rows slower, {} faster{}", c.slower(), c.timing.size(), c.faster(),
                     c.options.gate_timing ? " (gating)" : " (informs)");
  else
    s += fmt::format("; timing not compared ({})", c.timing_note);
  return s;
}

std::string format_text(const comparison& c) { return report(c, table_format::text); }
std::string format_markdown(const comparison& c) { return report(c, table_format::markdown); }

}  // namespace stepbench

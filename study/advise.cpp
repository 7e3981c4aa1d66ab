#include "study/advise.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "study/h5.hpp"
#include "study/table_render.hpp"

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
  switch (m.origin) {
    case method_origin::peer:
      return m.name + " (peer)";
    case method_origin::baseline:
      return m.name + " (baseline, for scale)";
    default:
      return m.name;
  }
}

}  // namespace

advice advise(const study_data& study, const std::string& problem, const std::string& metric, double tol) {
  if (!is_error_metric(metric))
    throw std::invalid_argument(fmt::format("unknown metric '{}' (known: {})", metric, fmt::join(error_metrics, ", ")));
  if (!(tol > 0.0) || !std::isfinite(tol)) throw std::invalid_argument(fmt::format("--tol must be > 0, got {}", tol));
  const study_problem* p = study.find(problem);
  if (!p) {
    std::vector<std::string> names;
    for (const auto& q : study.problems) names.push_back(q.name);
    throw std::invalid_argument(fmt::format("problem '{}' is not in the study file '{}' (it has: {})", problem,
                                            study.path,
                                            names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
  }
  advice a;
  a.problem = problem;
  a.metric = metric;
  a.unit = metric == "err_vel_final" ? p->unit + "/s" : p->unit;
  a.tol = tol;
  a.timed = study.timed;
  a.methods = work_precision_input(*p, metric, study.timed);
  a.result = cheapest(a.methods, tol, study.timed, metric, a.unit);
  return a;
}

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
  std::vector<const wp_pick*> others;
  for (const auto& p : r.ranked)
    if (!answer || p.method != answer->method) others.push_back(&p);
  if (!others.empty()) {
    table t{{right_column("rank"),
             {"method"},
             {"dt or tolerance"},
             right_column("cost"),
             right_column(a.metric, a.unit),
             {"stability margin"}},
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
    table t{{{"method"}, {"reason"}}, {}};
    for (const auto& e : r.excluded) t.add({label(a.methods[e.method]), e.reason});
    out += "excluded:\n" + render_text(t);
  }
  return out;
}

frame_advice advise_frame(const std::string& path, const std::string& problem, double hz, double tol) {
  if (!(tol > 0.0) || !std::isfinite(tol)) throw std::invalid_argument(fmt::format("--tol must be > 0, got {}", tol));
  if (!(hz > 0.0) || !std::isfinite(hz)) throw std::invalid_argument(fmt::format("--hz must be > 0, got {}", hz));
  frame_advice f;
  f.problem = problem;
  f.hz = hz;
  f.tol = tol;
  std::vector<double> rate, substeps, completed, diverged, err, cost;
  std::vector<std::string> method, note;
  std::size_t rows = 0;
  try {
    if (!std::filesystem::exists(path)) throw std::runtime_error("no such file");
    if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
    const H5::H5File file(path, H5F_ACC_RDONLY);
    if (!h5::is_group(file, "frame_rates") || !h5::is_group(file, "verdict"))
      throw std::runtime_error("it has no frame-rate study (written before format_version 4: run the study again)");
    f.cost_kind = h5::string_attr(file.openGroup("verdict"), "cost_kind");
    const H5::Group all = file.openGroup("frame_rates");
    if (!h5::is_group(all, problem))
      throw std::invalid_argument(fmt::format("problem '{}' has no frame-rate runs in '{}' (it has: {})", problem, path,
                                              fmt::join(h5::children(all), ", ")));
    const H5::Group g = all.openGroup(problem);
    f.unit = h5::string_attr(g, "position_unit");
    f.horizon = h5::double_attr(g, "horizon");
    const h5::table_data runs = h5::read_table(g.openDataSet("runs"));
    rows = runs.rows();
    rate = runs.doubles("hz"), substeps = runs.doubles("substeps"), completed = runs.doubles("completed");
    diverged = runs.doubles("diverged"), err = runs.doubles("err_pos_max"), cost = runs.doubles("cost_per_frame");
    method = runs.strings("method"), note = runs.strings("note");
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read study file '{}': {}", path, e.getDetailMsg()));
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("cannot read study file '{}': {}", path, e.what()));
  }
  std::vector<double> rates;
  for (double r : rate)
    if (std::find(rates.begin(), rates.end(), r) == rates.end()) rates.push_back(r);
  if (std::find(rates.begin(), rates.end(), hz) == rates.end())
    throw std::invalid_argument(
        fmt::format("--hz {:g}: the study ran {} at {} Hz only", hz, problem, fmt::join(rates, ", ")));
  std::map<std::string, frame_option> best, closest;  // per method: cheapest meeting tol; lowest error
  std::vector<std::string> order;
  std::set<std::string> untimed;  // meets the tolerance in a run the benchmark did not time
  for (std::size_t i = 0; i < rows; ++i) {
    if (rate[i] != hz) continue;
    frame_option o{method[i], note[i], static_cast<int>(substeps[i]), completed[i] != 0, diverged[i] != 0,
                   err[i],    cost[i]};
    if (std::find(order.begin(), order.end(), o.method) == order.end()) order.push_back(o.method);
    if (o.substeps == 1) f.one_step.push_back(o);
    if (!o.completed || !std::isfinite(o.err_pos_max)) continue;
    if (!closest.count(o.method) || o.err_pos_max < closest[o.method].err_pos_max) closest[o.method] = o;
    if (o.err_pos_max <= tol && !std::isfinite(o.cost_per_frame)) untimed.insert(o.method);
    if (o.err_pos_max <= tol && std::isfinite(o.cost_per_frame) &&
        (!best.count(o.method) || o.cost_per_frame < best[o.method].cost_per_frame))
      best[o.method] = o;
  }
  for (const auto& m : order) {
    if (best.count(m))
      f.ranked.push_back(best[m]);
    else if (untimed.count(m))
      f.not_meeting.push_back(
          fmt::format("{}: meets it, but the benchmark did not time it on {} (no cost a frame)", m, problem));
    else if (closest.count(m))
      f.not_meeting.push_back(fmt::format("{}: best {:.3g} {} at {} substep{}", m, closest[m].err_pos_max, f.unit,
                                          closest[m].substeps, closest[m].substeps == 1 ? "" : "s"));
    else
      f.not_meeting.push_back(fmt::format("{}: diverged or failed at every substep count", m));
  }
  std::stable_sort(f.ranked.begin(), f.ranked.end(), [](const frame_option& a, const frame_option& b) {
    return a.cost_per_frame != b.cost_per_frame ? a.cost_per_frame < b.cost_per_frame : a.err_pos_max < b.err_pos_max;
  });
  return f;
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
  if (f.ranked.size() > 1) {
    table t{{{"method"}, right_column("substeps"), right_column("err_pos_max", f.unit), right_column("cost a frame")},
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
  table t{{{"method"}, {"one step a frame"}, right_column("err_pos_max", f.unit)}, {}};
  for (const auto& o : f.one_step)
    t.add({o.method, o.completed ? "stable" : (o.diverged ? "diverges" : "fails: " + o.note),
           o.completed ? fmt::format("{:.3g}", o.err_pos_max) : "-"});
  out += fmt::format("at one step a frame (dt {:.3g} ms):\n", frame_ms) + render_text(t);
  return out;
}

}  // namespace stepbench

#include "store/scan.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "core/number.hpp"
#include "core/text.hpp"
#include "store/columns.hpp"
#include "store/study_reader.hpp"

namespace stepbench {
namespace {

const auto scan_point_columns = column_map<scan_point>("scan_points", "/scan/<name>/points")
                                    .member("point", &scan_point::index)
                                    .member("trusted", &scan_point::trusted)
                                    .member("truth_source", &scan_point::truth_source)
                                    .member("horizon", &scan_point::horizon)
                                    .member("pos_scale", &scan_point::pos_scale)
                                    .member("note", &scan_point::note);

// A run's counts are stored as doubles (a frame's share of them is not whole).
template <long work_counters::*count>
double counted(const scan_run& r) {
  return static_cast<double>(r.row.work.*count);
}
template <long work_counters::*count>
void set_counted(scan_run& r, double v) {
  r.row.work.*count = static_cast<long>(v);
}

const auto scan_run_columns =
    column_map<scan_run>("scan_runs", "/scan/<name>/runs")
        .member("point", &scan_run::point)
        .member("hz", &scan_run::hz)
        .member("method", &scan_run::method)
        .member("substeps", &scan_run::substeps)
        .member("dt", &scan_run::row, &method_row::param)
        .derived("completed", [](const scan_run& r) { return r.row.metrics.completed(); })
        .member("diverged", &scan_run::row, &method_row::metrics, &run_metrics::diverged)
        .member("failed", &scan_run::row, &method_row::metrics, &run_metrics::failed)
        .member("skipped", &scan_run::row, &method_row::metrics, &run_metrics::skipped)
        .field(
            "err_pos_max",
            [](const scan_run& r) { return r.row.metrics.completed() ? r.row.metrics.err_pos_max : nan; },
            [](scan_run& r, double v) { r.row.metrics.err_pos_max = v; })
        .member("steps", &scan_run::row, &method_row::steps)
        .field("force_evals", counted<&work_counters::force_evals>, set_counted<&work_counters::force_evals>)
        .field("newton_iterations", counted<&work_counters::newton_iterations>,
               set_counted<&work_counters::newton_iterations>)
        .member("note", &scan_run::row, &method_row::metrics, &run_metrics::note);

const auto scan_best_columns = column_map<scan_best>("scan_best", "/scan/<name>/best")
                                   .member("point", &scan_best::point)
                                   .member("hz", &scan_best::hz)
                                   .member("method", &scan_best::method)
                                   .member("substeps", &scan_best::substeps)
                                   .member("err_pos_max", &scan_best::err_pos_max)
                                   .member("force_evals_per_frame", &scan_best::force_evals_per_frame);

// /scan/<which>, from a file the reader has checked.
scan_result read_scan_group(const H5::Group& all, const std::string& which) {
  scan_result s;
  const H5::Group g = all.openGroup(which);
  auto& o = s.options;
  o.name = which;
  o.problem = h5::string_attr(g, "problem");
  s.unit = h5::string_attr(g, "unit");
  o.tol = h5::double_attr(g, "tol");
  const auto lo = h5::double_array_attr(g, "axis_lo"), hi = h5::double_array_attr(g, "axis_hi");
  const auto count = h5::int_array_attr(g, "axis_count"), log = h5::int_array_attr(g, "axis_log");
  const std::vector<std::string> axis_names = stored_list(h5::string_attr(g, "axes"), ',');
  if (axis_names.size() != lo.size() || lo.size() != hi.size() || hi.size() != count.size() ||
      count.size() != log.size())
    throw std::runtime_error(fmt::format("scan '{}': its axis attributes differ in length", which));
  for (std::size_t k = 0; k < axis_names.size(); ++k)
    o.axes.push_back({axis_names[k], lo[k], hi[k], static_cast<int>(count[k]), log[k] != 0, false});
  o.hz = h5::double_array_attr(g, "hz");
  o.substeps.clear();  // the file's counts replace the defaults, not extend them
  for (long n : h5::int_array_attr(g, "substeps")) o.substeps.push_back(static_cast<int>(n));
  o.methods = stored_list(h5::string_attr(g, "methods"), ',');
  const auto fixed_names = stored_list(h5::string_attr(g, "fixed_params"), ',');
  const auto fixed_values = h5::double_array_attr(g, "fixed_values");
  if (fixed_names.size() != fixed_values.size())
    throw std::runtime_error(
        fmt::format("scan '{}': {} fixed_params but {} fixed_values", which, fixed_names.size(), fixed_values.size()));
  for (std::size_t k = 0; k < fixed_names.size(); ++k) o.fixed[fixed_names[k]] = fixed_values[k];
  if (g.attrExists("cost_source")) {  // a scan written before the measured costs ranks by evaluations
    o.cost_source = h5::string_attr(g, "cost_source");
    const auto cost_methods = stored_list(h5::string_attr(g, "cost_methods"), ',');
    const auto cost_values = h5::double_array_attr(g, "cost_ns_per_force_eval");
    if (cost_methods.size() != cost_values.size())
      throw std::runtime_error(fmt::format("scan '{}': {} cost_methods but {} cost_ns_per_force_eval", which,
                                           cost_methods.size(), cost_values.size()));
    for (std::size_t k = 0; k < cost_methods.size(); ++k) {
      if (!(cost_values[k] > 0.0 && std::isfinite(cost_values[k])))
        throw std::runtime_error(
            fmt::format("scan '{}': cost of {} is {}, not a positive time", which, cost_methods[k], cost_values[k]));
      o.ns_per_force_eval[cost_methods[k]] = cost_values[k];
    }
  }
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
  s.points = scan_point_columns.read(g, "points");
  std::map<std::size_t, std::size_t> local_of;  // grid index -> row
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    auto& p = s.points[i];
    for (const auto& c : columns) {
      if (c.size() != s.points.size())
        throw std::runtime_error(fmt::format("scan '{}': values/ and points differ in length", which));
      p.values.push_back(c[i]);
    }
    if (p.index >= s.grid_points || local_of.count(p.index))
      throw std::runtime_error(fmt::format("scan '{}': point {} is outside its grid of {} or repeated", which,
                                           static_cast<std::int64_t>(p.index), s.grid_points));
    local_of[p.index] = i;
  }
  s.runs = scan_run_columns.read(g, "runs");
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    auto& r = s.runs[i];
    const auto at = local_of.find(r.point);
    if (at == local_of.end())
      throw std::runtime_error(fmt::format("scan '{}': run {} names point {}, which its points table lacks", which, i,
                                           static_cast<std::int64_t>(r.point)));
    r.point = at->second;
  }
  compute_best(s);
  return s;
}

}  // namespace

std::vector<schema::table> scan_tables() {
  return {scan_point_columns.spec(), scan_run_columns.spec(), scan_best_columns.spec()};
}

std::vector<scan_result> read_scans(const std::string& path) {
  study file = std::move(read_studies({path}, [](const H5::Group& root, study& s) {
                           if (!h5::is_group(root, "scan"))
                             throw std::runtime_error("it holds no scan (/scan is absent)");
                           const H5::Group all = root.openGroup("scan");
                           auto& scans = s.results.put(std::vector<scan_result>{});
                           for (const auto& name : h5::children(all)) scans.push_back(read_scan_group(all, name));
                         }).front());
  std::vector<scan_result> scans = std::move(*file.results.find<std::vector<scan_result>>());
  for (auto& sc : scans) sc.source = path;
  return scans;
}

scan_result read_scan(const std::string& path, const std::string& name) {
  std::vector<scan_result> scans = read_scans(path);
  std::vector<std::string> names;
  for (const auto& s : scans) names.push_back(s.options.name);
  if (name.empty() && scans.size() != 1)
    throw std::invalid_argument(
        fmt::format("'{}' holds {} scans; name one with --name ({})", path, scans.size(), fmt::join(names, ", ")));
  for (auto& s : scans)
    if (name.empty() || s.options.name == name) return std::move(s);
  throw std::invalid_argument(fmt::format("'{}' has no scan '{}' (it has: {})", path, name, fmt::join(names, ", ")));
}

std::string file_build(const std::string& path) {
  // The compiler and the libraries too: another GSL or SUNDIALS is another truth.
  const study file = std::move(read_studies({path}, [](const H5::Group&, study&) {}).front());
  const study_record& r = *file.record;
  const auto meta = [&](const char* key) {
    const auto it = r.meta.find(key);
    if (it == r.meta.end())
      throw std::runtime_error(fmt::format("cannot read study file '{}': no root attribute '{}'", path, key));
    return it->second;
  };
  return fmt::format("format_version {}, commit {}, {} build, flags {}, {}, {}", r.format_version, meta("git_commit"),
                     meta("build_type"), meta("build_flags"), meta("compiler"), meta("dependencies"));
}

void write_scans(H5::Group& root, const std::vector<scan_result>& scans) {
  using h5::attr;
  if (scans.empty()) return;
  H5::Group all = root.createGroup("scan");
  for (const auto& sc : scans) {
    const auto& o = sc.options;
    H5::Group g = all.createGroup(o.name.empty() ? o.problem : o.name);
    attr(g, "problem", o.problem);
    attr(g, "unit", sc.unit);
    attr(g, "tol", o.tol);
    std::vector<std::string> axis_names;
    std::vector<double> lo, hi;
    std::vector<int> count, log;
    for (const auto& a : o.axes) {
      axis_names.push_back(a.param);
      lo.push_back(a.lo);
      hi.push_back(a.hi);
      count.push_back(a.count);
      log.push_back(a.log ? 1 : 0);
    }
    attr(g, "axes", fmt::format("{}", fmt::join(axis_names, ",")));  // parameter names have no commas
    attr(g, "axis_lo", lo);
    attr(g, "axis_hi", hi);
    attr(g, "axis_count", count);
    attr(g, "axis_log", log);
    attr(g, "hz", o.hz);
    attr(g, "substeps", std::vector<int>(o.substeps.begin(), o.substeps.end()));
    attr(g, "methods", fmt::format("{}", fmt::join(o.methods, ",")));  // the methods run; names have no commas
    std::vector<std::string> fixed_names;
    std::vector<double> fixed_values;
    for (const auto& [name, value] : o.fixed) {
      fixed_names.push_back(name);
      fixed_values.push_back(value);
    }
    attr(g, "fixed_params", fmt::format("{}", fmt::join(fixed_names, ",")));
    attr(g, "fixed_values", fixed_values);
    std::vector<std::string> cost_methods;
    std::vector<double> cost_values;
    for (const auto& [name, ns] : o.ns_per_force_eval) {
      cost_methods.push_back(name);
      cost_values.push_back(ns);
    }
    attr(g, "cost_source", o.cost_source);
    attr(g, "cost_methods", fmt::format("{}", fmt::join(cost_methods, ",")));
    attr(g, "cost_ns_per_force_eval", cost_values);
    attr(g, "reference_rtol", o.ref_tol.rtol);
    attr(g, "reference_atol", o.ref_tol.atol);
    attr(g, "work_budget", o.limits.work_budget);
    attr(g, "reference_budget", o.reference_budget);
    attr(g, "range_answer", sc.range_answer);
    attr(g, "wall_seconds", sc.wall_seconds);
    attr(g, "grid_points", static_cast<long>(sc.grid_points));
    attr(g, "shard_index", o.shard_index);
    attr(g, "shard_count", o.shard_count);
    // The grid: one 1-D dataset per axis under values/, a value per point.
    H5::Group values = g.createGroup("values");
    for (std::size_t k = 0; k < o.axes.size(); ++k) {
      std::vector<double> column;
      for (const auto& p : sc.points) column.push_back(p.values[k]);
      h5::dataset(values, o.axes[k].param, column);
    }
    scan_point_columns.write(g, "points", sc.points);
    // Runs and answers name their point by its place in the whole grid.
    std::vector<scan_run> runs = sc.runs;
    for (auto& r : runs) r.point = sc.points[r.point].index;
    scan_run_columns.write(g, "runs", runs);
    std::vector<scan_best> best = sc.best;
    for (auto& b : best) b.point = sc.points[b.point].index;
    scan_best_columns.write(g, "best", best);
  }
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
    std::vector<std::string> costs;  // the ranking's: shards ranked alike, or the merged answer mixes them
    for (const auto& [name, ns] : o.ns_per_force_eval) costs.push_back(fmt::format("{}={}", name, ns));
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
        {"ranking costs (--costs)",
         costs.empty() ? "force evaluations" : fmt::format("{} from {}", fmt::join(costs, ","), o.cost_source)},
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

}  // namespace stepbench

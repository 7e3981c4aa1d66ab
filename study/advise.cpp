#include "core/advise.hpp"

#include <H5Cpp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace stepbench {
namespace {

bool link_exists(const H5::Group& g, const std::string& name) {
  return H5Lexists(g.getId(), name.c_str(), H5P_DEFAULT) > 0;
}

bool is_dataset(const H5::Group& g, const std::string& name) {
  return link_exists(g, name) && g.childObjType(name) == H5O_TYPE_DATASET;
}

bool has_field(const H5::DataSet& ds, const std::string& field) {
  if (ds.getTypeClass() != H5T_COMPOUND) return false;
  const H5::CompType t = ds.getCompType();
  for (int i = 0; i < t.getNmembers(); ++i)
    if (t.getMemberName(i) == field) return true;
  return false;
}

// One field of a compound dataset, converted by HDF5 to T (fields are matched by name,
// so the reader does not depend on the writer's layout or on the other fields).
template <class T>
std::vector<T> read_field(const H5::DataSet& ds, const std::string& field, const H5::PredType& type) {
  const hssize_t n = ds.getSpace().getSimpleExtentNpoints();
  std::vector<T> out(static_cast<std::size_t>(n));
  if (n == 0) return out;
  H5::CompType mem(sizeof(T));
  mem.insertMember(field, 0, type);
  ds.read(out.data(), mem);
  return out;
}

std::vector<double> read_doubles(const H5::DataSet& ds, const std::string& field) {
  return read_field<double>(ds, field, H5::PredType::NATIVE_DOUBLE);
}

std::string string_attr(const H5::H5Object& obj, const std::string& name, const std::string& fallback) {
  if (!obj.attrExists(name)) return fallback;
  const H5::Attribute a = obj.openAttribute(name);
  if (a.getTypeClass() != H5T_STRING) return fallback;
  std::string value;
  a.read(a.getStrType(), value);
  return value;
}

// The position unit: the study format says metres, or radians for the pendulum (whose
// state is the angle). A `position_unit` attribute, if a later writer adds one, wins.
std::string position_unit(const H5::Group& g, const std::string& problem) {
  return string_attr(g, "position_unit", problem == "pendulum" ? "rad" : "m");
}

advise_method read_method(const H5::DataSet& ds, const std::string& name, bool peer, const std::string& metric,
                          bool& timed) {
  advise_method m;
  m.name = name;
  m.peer = peer;
  const std::string param_field = peer ? "param" : "dt";
  const auto param = read_doubles(ds, param_field);
  const auto evals = read_field<std::int64_t>(ds, "force_evals", H5::PredType::NATIVE_INT64);
  m.has_metric = has_field(ds, metric);
  const auto err = m.has_metric ? read_doubles(ds, metric) : std::vector<double>(param.size(), NAN);
  // Integrators record `diverged`; peers may not, and then a non-finite error is the sign.
  const auto diverged = has_field(ds, "diverged") ? read_field<std::int8_t>(ds, "diverged", H5::PredType::NATIVE_INT8)
                                                  : std::vector<std::int8_t>(param.size(), 0);
  const bool has_time = has_field(ds, "time_ns");
  timed = has_time;
  const auto time = has_time ? read_doubles(ds, "time_ns") : std::vector<double>(param.size(), NAN);
  const auto cut = has_field(ds, "cut") ? read_field<std::int8_t>(ds, "cut", H5::PredType::NATIVE_INT8)
                                        : std::vector<std::int8_t>(param.size(), 0);
  // Errors that are NaN/Inf mean a failed run even where no flag says so; errors that
  // only lack the metric (has_metric false) do not.
  const auto e_pos = has_field(ds, "err_pos_max") ? read_doubles(ds, "err_pos_max") : err;
  for (std::size_t i = 0; i < param.size(); ++i) {
    advise_row r;
    r.param = param[i];
    r.force_evals = evals[i];
    r.error = err[i];
    r.time_ns = time[i];
    r.cut = cut[i] != 0;
    r.diverged = diverged[i] != 0 || !std::isfinite(e_pos[i]) || (m.has_metric && !std::isfinite(err[i]));
    m.rows.push_back(r);
  }
  return m;
}

bool qualifies(const advise_row& r, double tol, bool timings) {
  return !r.diverged && std::isfinite(r.error) && r.error <= tol && !(timings && r.cut);
}

std::string param_text(double param, bool adaptive) {
  return adaptive ? fmt::format("rtol {:g}", param) : fmt::format("dt {:g} s", param);
}

std::string cost_text(const std::string& cost, const advise_row& r) {
  if (cost == "force_evals") return fmt::format("{} force evals", r.force_evals);
  const double ns = r.time_ns;
  if (ns >= 1e9) return fmt::format("{:.3g} s", ns * 1e-9);
  if (ns >= 1e6) return fmt::format("{:.3g} ms", ns * 1e-6);
  if (ns >= 1e3) return fmt::format("{:.3g} us", ns * 1e-3);
  return fmt::format("{:.3g} ns", ns);
}

std::string metric_unit(const std::string& metric, const std::string& unit) {
  return metric == "err_vel_final" ? unit + "/s" : unit;
}

}  // namespace

std::string format_param(const advise_pick& p) { return param_text(p.row.param, p.adaptive); }

advise_input read_advise_input(const std::string& study_path, const std::string& problem, const std::string& metric) {
  if (std::find(std::begin(advise_metrics), std::end(advise_metrics), metric) == std::end(advise_metrics))
    throw std::invalid_argument(fmt::format("unknown metric '{}' (known: {})", metric, fmt::join(advise_metrics, ", ")));
  std::error_code ec;
  if (!std::filesystem::exists(study_path, ec))
    throw std::runtime_error(fmt::format("cannot read study file '{}': no such file", study_path));
  H5::Exception::dontPrint();
  advise_input in;
  in.problem = problem;
  in.metric = metric;
  try {
    if (!H5::H5File::isHdf5(study_path))
      throw std::runtime_error(fmt::format("cannot read study file '{}': not an HDF5 file", study_path));
    const H5::H5File file(study_path, H5F_ACC_RDONLY);
    if (!file.attrExists("format_version"))
      throw std::runtime_error(fmt::format("cannot read study file '{}': not a stepbench study (no format_version)", study_path));
    std::vector<std::string> problems;
    for (hsize_t i = 0; i < file.getNumObjs(); ++i) {
      const std::string name = file.getObjnameByIdx(i);
      if (file.childObjType(name) == H5O_TYPE_GROUP) problems.push_back(name);
    }
    if (std::find(problems.begin(), problems.end(), problem) == problems.end())
      throw std::invalid_argument(fmt::format("problem '{}' is not in the study file '{}' (it has: {})", problem,
                                              study_path, problems.empty() ? "none" : fmt::format("{}", fmt::join(problems, ", "))));
    const H5::Group g = file.openGroup(problem);
    in.unit = position_unit(g, problem);
    bool all_timed = true, any = false;
    // Integrator groups hold `convergence`, peer groups `work_precision` (the format's
    // rule); `reference` and anything else is not a candidate.
    for (hsize_t i = 0; i < g.getNumObjs(); ++i) {
      const std::string name = g.getObjnameByIdx(i);
      if (name == "reference" || g.childObjType(name) != H5O_TYPE_GROUP) continue;
      const H5::Group m = g.openGroup(name);
      const bool integrator = is_dataset(m, "convergence");
      if (!integrator && !is_dataset(m, "work_precision")) continue;
      bool timed = false;
      advise_method am = read_method(m.openDataSet(integrator ? "convergence" : "work_precision"), name, !integrator,
                                     metric, timed);
      am.adaptive = !integrator && string_attr(m, "kind", "fixed_step") == "adaptive";
      all_timed = all_timed && timed;
      any = true;
      in.methods.push_back(std::move(am));
    }
    in.timings = any && all_timed;
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read study file '{}': HDF5: {}", study_path, e.getDetailMsg()));
  }
  return in;
}

advise_result advise(const advise_input& in, double tol) {
  if (!(tol > 0.0) || !std::isfinite(tol)) throw std::invalid_argument(fmt::format("--tol must be > 0, got {}", tol));
  advise_result r;
  r.problem = in.problem;
  r.metric = in.metric;
  r.unit = metric_unit(in.metric, in.unit);
  r.tol = tol;
  r.timings = in.timings;

  // Time is the cost only if it can rank every qualifying row; otherwise the counted
  // force evaluations, which every row has.
  bool all_timed = in.timings;
  for (const auto& m : in.methods)
    for (const auto& row : m.rows)
      if (qualifies(row, tol, in.timings) && !(std::isfinite(row.time_ns) && row.time_ns > 0.0)) all_timed = false;
  r.cost = all_timed ? "time_ns" : "force_evals";
  auto cost_of = [&](const advise_row& row) {
    return all_timed ? row.time_ns : static_cast<double>(row.force_evals);
  };

  for (const auto& m : in.methods) {
    auto make_pick = [&](const advise_row& row) {
      advise_pick p;
      p.method = m.name;
      p.peer = m.peer;
      p.adaptive = m.adaptive;
      p.row = row;
      p.cost = cost_of(row);
      for (const auto& d : m.rows) {
        if (!d.diverged) continue;
        ++p.diverged_rows;
        if (!p.largest_diverged || d.param > *p.largest_diverged) p.largest_diverged = d.param;
        if (!p.smallest_diverged || d.param < *p.smallest_diverged) p.smallest_diverged = d.param;
      }
      return p;
    };
    const advise_row* best = nullptr;
    for (const auto& row : m.rows) {
      if (!qualifies(row, tol, in.timings)) continue;
      // Cheapest; on a tie the more accurate row.
      if (!best || cost_of(row) < cost_of(*best) || (cost_of(row) == cost_of(*best) && row.error < best->error))
        best = &row;
    }
    // Lowest error achieved by this method in the file (for the reasons and for "best achieved").
    const advise_row* lowest = nullptr;
    for (const auto& row : m.rows)
      if (!row.diverged && std::isfinite(row.error) && (!lowest || row.error < lowest->error)) lowest = &row;
    if (lowest && (!r.best_achieved || lowest->error < r.best_achieved->row.error)) r.best_achieved = make_pick(*lowest);
    if (best) {
      r.ranked.push_back(make_pick(*best));
      continue;
    }
    const std::string what = m.adaptive ? "tolerance" : "dt";
    std::string reason;
    if (!m.has_metric) {
      reason = fmt::format("no {} recorded for this peer", in.metric);
    } else if (!lowest) {
      reason = m.rows.empty() ? "no rows in the study" : fmt::format("diverged at every {}", what);
    } else if (lowest->error <= tol) {  // accurate enough, but every such row was cut
      reason = fmt::format("too slow: cut by the time budget (would reach {} {:.3g} {} at {})", in.metric, lowest->error,
                           r.unit, param_text(lowest->param, m.adaptive));
    } else {
      reason = fmt::format("too inaccurate: best {} {:.3g} {} at {}", in.metric, lowest->error, r.unit,
                           param_text(lowest->param, m.adaptive));
    }
    r.excluded.push_back({m.name, reason});
  }
  std::stable_sort(r.ranked.begin(), r.ranked.end(), [](const advise_pick& a, const advise_pick& b) {
    if (a.cost != b.cost) return a.cost < b.cost;
    if (a.row.error != b.row.error) return a.row.error < b.row.error;
    return a.method < b.method;
  });
  if (!r.ranked.empty()) r.best_achieved.reset();
  return r;
}

std::string format_advice(const advise_result& r, std::size_t runners_up) {
  std::string out;
  const std::string cost_name = r.cost == "time_ns" ? "measured time per run (median)"
                                : r.timings        ? "force evaluations (some qualifying rows are not timed)"
                                                   : "force evaluations (the study has no timings)";
  // The stability margin: how far the chosen row is from the rows that blew up.
  auto margin = [](const advise_pick& p) {
    if (!p.largest_diverged) return std::string("never diverged in the study");
    if (p.diverged_rows == 1) return fmt::format("diverged at {}", param_text(*p.largest_diverged, p.adaptive));
    return fmt::format("diverged at {} rows: {} .. {}", p.diverged_rows, param_text(*p.smallest_diverged, p.adaptive),
                       param_text(*p.largest_diverged, p.adaptive));
  };
  auto line = [&](const advise_pick& p) {
    return fmt::format("{:<27} {:<18} {:>18}  {} {:.3g} {}  [{}]", p.method + (p.peer ? " (peer)" : ""),
                       format_param(p), cost_text(r.cost, p.row), r.metric, p.row.error, r.unit, margin(p));
  };
  out += fmt::format("{}: {} <= {:g} {}; cost = {}\n", r.problem, r.metric, r.tol, r.unit, cost_name);
  if (r.ranked.empty()) {
    out += fmt::format("no method in the study meets {} <= {:g} {} on {}", r.metric, r.tol, r.unit, r.problem);
    if (r.best_achieved)
      out += fmt::format("; the best achieved is {} {:.3g} {} by {} at {}", r.metric, r.best_achieved->row.error, r.unit,
                         r.best_achieved->method, format_param(*r.best_achieved));
    out += "\n";
  } else {
    const auto& w = r.ranked.front();
    out += fmt::format("use {} at {}: {}, {} {:.3g} {}; {}\n", w.method + (w.peer ? " (peer)" : ""), format_param(w),
                       cost_text(r.cost, w.row), r.metric, w.row.error, r.unit, margin(w));
    if (r.ranked.size() > 1) {
      out += "runners-up:\n";
      for (std::size_t i = 1; i < r.ranked.size() && i <= runners_up; ++i)
        out += fmt::format("  {}. {}\n", i + 1, line(r.ranked[i]));
      if (r.ranked.size() > runners_up + 1)
        out += fmt::format("  ... and {} more that also meet the tolerance\n", r.ranked.size() - runners_up - 1);
    }
  }
  if (!r.excluded.empty()) {
    out += "excluded:\n";
    for (const auto& e : r.excluded) out += fmt::format("  {:<27} {}\n", e.method, e.reason);
  }
  return out;
}

}  // namespace stepbench

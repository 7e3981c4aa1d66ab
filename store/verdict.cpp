#include "store/verdict.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>

#include "core/number.hpp"
#include "judge/substeps.hpp"
#include "judge/verdict.hpp"
#include "store/h5.hpp"
#include "store/study_file.hpp"

namespace stepbench {

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
      for (std::size_t i = 0; i < t.rows(); ++i) {
        substep_verdict sv{p,      im[i],     em[i], kind[i],
                           ic[i],  ie[i],     id[i], static_cast<int>(at_cost[i]),
                           ec[i],  ee[i],     ed[i], static_cast<int>(to_match[i]),
                           ctm[i], summary[i]};
        if (is_first_order_pair(sv)) in.substeps.push_back({p, frame_dt, std::move(sv)});
      }
    }
    if (h5::is_group(root, "problems/" + p + "/methods")) {
      const H5::Group methods = root.openGroup("problems/" + p + "/methods");
      for (const auto& m : h5::children(methods)) {
        const H5::Group g = methods.openGroup(m);
        if (h5::string_attr(g, "origin") == "peer" && h5::long_attr(g, "declared_order_holds") == 0)
          in.broken_orders[m].insert(p);
      }
      for (const auto& m : h5::children(methods)) {
        if (!judges_ladder_as_substeps(m)) continue;
        const auto t = h5::read_table(methods.openGroup(m).openDataSet("runs"));
        const auto dt = t.doubles("param"), drift = t.doubles("energy_drift");
        // A study written before the field reads as NaN (as study_reader.cpp does).
        const auto constraint = t.has("constraint_violation_max") ? t.doubles("constraint_violation_max")
                                                                  : std::vector<double>(t.rows(), nan);
        const auto &diverged = t.ints("diverged"), &failed = t.ints("failed"), &skipped = t.ints("skipped");
        ladder_finding f{m, p, {}};
        for (std::size_t i = 0; i < t.rows(); ++i)
          f.runs.push_back({dt[i], diverged[i] != 0, failed[i] != 0, skipped[i] != 0, drift[i], constraint[i]});
        in.small_steps_ladders.push_back(std::move(f));
      }
    }
  }
  return in;
}

void judge_findings_again(H5::Group& root, const std::vector<std::string>& problems) {
  const auto findings = findings_of(read_verdict(root), read_finding_inputs(root, problems));
  H5::Group g = root.openGroup("verdict");
  if (g.attrExists("findings")) g.removeAttr("findings");
  h5::attr(g, "findings", fmt::format("{}", fmt::join(findings, "\n")));
}

void write_verdict(H5::Group& root, const study& s) {
  using h5::attr;
  const verdict_tables* found = s.results.find<verdict_tables>();
  if (!found) return;
  const verdict_tables& v = *found;
  H5::Group g = root.createGroup("verdict");
  attr(g, "metric", verdict_metric);
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

frame_rate_runs read_frame_rate_runs(const std::string& path, const std::string& problem) {
  frame_rate_runs f;
  f.problem = problem;
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
  for (std::size_t i = 0; i < rows; ++i)
    f.runs.push_back({method[i], note[i], rate[i], static_cast<int>(substeps[i]), completed[i] != 0, diverged[i] != 0,
                      err[i], cost[i]});
  return f;
}

}  // namespace stepbench

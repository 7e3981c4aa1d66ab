#include "store/challenge.hpp"

#include "store/h5.hpp"
#include "store/schema.hpp"

namespace stepbench {

void write_challenge(H5::Group& root, const challenge_result& r) {
  H5::Group g = root.createGroup("challenge");
  h5::attr(g, "hz", r.options.hz);
  h5::attr(g, "xpbd_substeps", r.options.xpbd_substeps);
  h5::attr(g, "horizon", r.options.horizon);
  h5::attr(g, "energy_horizon", r.options.energy_horizon);
  h5::attr(g, "small_steps_time", r.options.small_steps_time);
  h5::attr(g, "energy_scale", r.energy_scale);
  h5::attr(g, "wall_seconds", r.seconds);
  {
    h5::table t;
    std::vector<std::string> method, note;
    std::vector<std::int64_t> k;
    std::vector<double> tol, ns, err, drift, emax, link, ns_eq;
    std::vector<std::int8_t> stable;
    for (const auto& e : r.entries) {
      method.push_back(e.method), note.push_back(e.note), k.push_back(e.steps_per_frame), tol.push_back(e.tolerance);
      ns.push_back(e.ns_per_frame), err.push_back(e.err_pos_max), drift.push_back(e.energy_drift);
      emax.push_back(e.energy_err_max), link.push_back(e.link_err_max), ns_eq.push_back(e.ns_per_frame_at_xpbd_error);
      stable.push_back(e.stable ? 1 : 0);
    }
    t.add("method", method);
    t.add("steps_per_frame", k);
    t.add("tolerance", tol);
    t.add("ns_per_frame", ns);
    t.add("err_pos_max", err);
    t.add("energy_drift", drift);
    t.add("energy_err_max", emax);
    t.add("link_err_max", link);
    t.add("stable", stable);
    t.add("ns_per_frame_at_xpbd_error", ns_eq);
    t.add("note", note);
    t.write(g, "entries", schema::find("challenge_entries"));
  }
  {
    h5::table t;
    std::vector<std::string> criterion = r.verdict_criteria, verdict = r.verdicts;
    for (const auto& v : r.small_steps_verdicts) criterion.push_back("small_steps"), verdict.push_back(v);
    t.add("criterion", criterion);
    t.add("verdict", verdict);
    t.write(g, "verdicts", schema::find("challenge_verdicts"));
  }
  {
    h5::table t;
    std::vector<std::string> problem, design;
    std::vector<std::int64_t> n;
    std::vector<double> err, link, work, ns;
    std::vector<std::int8_t> diverged;
    for (const auto& s : r.small_steps) {
      problem.push_back(s.problem), design.push_back(s.design), n.push_back(s.n), err.push_back(s.err_pos);
      link.push_back(s.link_err), work.push_back(s.work_per_frame), ns.push_back(s.ns_per_frame);
      diverged.push_back(s.diverged ? 1 : 0);
    }
    t.add("problem", problem);
    t.add("design", design);
    t.add("n", n);
    t.add("err_pos", err);
    t.add("link_err", link);
    t.add("work_per_frame", work);
    t.add("ns_per_frame", ns);
    t.add("diverged", diverged);
    t.write(g, "small_steps", schema::find("small_steps"));
  }
}

}  // namespace stepbench

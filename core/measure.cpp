#include "core/measure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "core/number.hpp"

namespace stepbench {
namespace {

double norm_diff(std::span<const double> a, std::span<const double> b, int offset, int dim) {
  double s = 0.0;
  for (int i = 0; i < dim; ++i) {
    const double d = a[offset + i] - b[offset + i];
    s += d * d;
  }
  return std::sqrt(s);
}

double norm_part(std::span<const double> y, int offset, int dim) {
  double s = 0.0;
  for (int i = 0; i < dim; ++i) s += y[offset + i] * y[offset + i];
  return std::sqrt(s);
}

// Kinetic energy of [x; v] is E([x; v]) - E([x; 0]) for every problem here (the
// potential depends on x only, the kinetic energy on v only), which needs no
// kinetic-energy hook in the interface. Evaluated at x = 0 for both terms.
double kinetic(const problem_instance& p, std::span<const double> y) {
  std::vector<double> moving(y.begin(), y.end()), rest(y.size(), 0.0);
  for (int i = 0; i < p.dim(); ++i) moving[i] = 0.0;
  return p.energy(moving) - p.energy(rest);
}

// States mapped to the positions errors are measured on (problem_instance::observed).
std::vector<std::vector<double>> observed_all(const problem_instance& p, std::span<const std::vector<double>> ys) {
  std::vector<std::vector<double>> out;
  out.reserve(ys.size());
  for (const auto& y : ys) out.push_back(p.observed(y));
  return out;
}

// compare() on the observed positions.
agreement compare_observed(const problem_instance& p, std::span<const std::vector<double>> a,
                           std::span<const std::vector<double>> b, const truth_table& t) {
  return compare(observed_all(p, a), observed_all(p, b), p.observed_dim(), t.pos_scale, t.vel_scale);
}

void set_scales(const problem_instance& p, truth_table& t) {
  const int dim = p.observed_dim();
  const auto y0 = p.initial();
  const auto o0 = p.observed(y0);
  double xs = norm_part(o0, 0, dim), vs = norm_part(o0, dim, dim);
  double es = p.has_energy() ? std::max(std::abs(p.energy(y0)), kinetic(p, y0)) : 1.0;
  for (const auto& y : t.y) {
    const auto o = p.observed(y);
    xs = std::max(xs, norm_part(o, 0, dim));
    vs = std::max(vs, norm_part(o, dim, dim));
    if (p.has_energy()) es = std::max({es, std::abs(p.energy(y)), kinetic(p, y)});
  }
  if (p.has_angular_momentum()) {
    double ls = std::abs(p.angular_momentum(y0));
    for (const auto& y : t.y) ls = std::max(ls, std::abs(p.angular_momentum(y)));
    t.angmom_scale = ls > 0.0 ? ls : 1.0;
  }
  t.pos_scale = xs > 0.0 ? xs : 1.0;
  t.vel_scale = vs > 0.0 ? vs : 1.0;
  t.energy_scale = es > 0.0 ? es : 1.0;
}

std::string disagreement(const agreement& a, double limit) {
  return fmt::format("relative error {:.3e} (position) {:.3e} (velocity) exceeds the agreement limit {:.1e}", a.pos_rel,
                     a.vel_rel, limit);
}

}  // namespace

agreement compare(std::span<const std::vector<double>> a, std::span<const std::vector<double>> b, int dim,
                  double pos_scale, double vel_scale) {
  agreement out;
  for (size_t j = 0; j < a.size(); ++j) {
    out.pos_rel = std::max(out.pos_rel, norm_diff(a[j], b[j], 0, dim) / pos_scale);
    out.vel_rel = std::max(out.vel_rel, norm_diff(a[j], b[j], dim, dim) / vel_scale);
  }
  return out;
}

namespace {

// Every reference source on the problem: solved, failed with its reason, or unsupported.
std::vector<reference_check> run_references(const problem_instance& problem, std::span<const double> times,
                                            const truth_options& opts) {
  std::vector<reference_check> out;
  const ode_system sys = problem.ode();
  for (const char* source : reference_sources) {
    reference_check rc;
    rc.source = source;
    if (sys.has_contacts() && !reference_handles_contacts(source)) {
      rc.status = "unsupported";
      rc.reason = "the problem has contacts, and this reference has no root finding to stop at them";
      out.push_back(std::move(rc));
      continue;
    }
    try {
      rc.solution = solve_reference(source, sys, times, opts.tol);
    } catch (const std::runtime_error& e) {
      rc.status = "failed";
      rc.reason = e.what();
    }
    out.push_back(std::move(rc));
  }
  return out;
}

// Marks a reference that strays from what it was compared with beyond the limit.
void judge_agreement(reference_check& r, const truth_table& t) {
  if (!(r.vs.worst() <= t.agreement_limit)) r.status = "disagrees", r.reason = disagreement(r.vs, t.agreement_limit);
}

// The truth from the closed form; each completed reference is checked against it.
void truth_from_closed_form(const problem_instance& problem, truth_table& t, const std::vector<reference_check*>& ok) {
  t.source = "closed_form";
  for (double time : t.times) t.y.push_back(problem.exact(time));
  for (std::size_t j = 0; j < t.y.size(); ++j)
    for (double value : t.y[j])
      if (!std::isfinite(value))
        throw std::runtime_error(
            fmt::format("the closed form of problem {} is not finite at t = {:g}: are the parameters in range?",
                        problem.name(), t.times[j]));
  set_scales(problem, t);
  for (auto* r : ok) {
    r->compared_with = t.source;
    r->vs = compare_observed(problem, r->solution.y, t.y, t);
    judge_agreement(*r, t);
  }
}

// The truth from the best-agreeing pair of completed references (on scales from the
// first of them), trusted when they agree within the limit; else no trusted truth.
void truth_from_references(const problem_instance& problem, truth_table& t, const std::vector<reference_check*>& ok) {
  const int dim = problem.dim();
  if (!ok.empty()) {
    t.y = ok.front()->solution.y;
    set_scales(problem, t);
  }
  std::size_t best_i = 0, best_k = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ok.size(); ++i)
    for (std::size_t k = i + 1; k < ok.size(); ++k) {
      const double w = compare_observed(problem, ok[i]->solution.y, ok[k]->solution.y, t).worst();
      if (w < best) best = w, best_i = i, best_k = k;
    }
  if (ok.size() < 2 || !(best <= t.agreement_limit)) {
    t.trusted = false;
    t.source = "none";
    t.note = ok.size() < 2 ? fmt::format("only {} of {} references completed, and no closed form to check them",
                                         ok.size(), t.references.size())
                           : fmt::format("no two references agree within {:.1e} (best pair {} and {}: {:.3e})",
                                         t.agreement_limit, ok[best_i]->source, ok[best_k]->source, best);
    t.y.assign(t.times.size(), std::vector<double>(2 * dim, nan));
    for (auto* r : ok) r->status = "disagrees", r->reason = t.note;
    return;
  }
  reference_check& truth = *ok[best_i];
  t.source = truth.source;
  t.y = truth.solution.y;
  set_scales(problem, t);
  for (auto* r : ok) {
    // The truth itself is reported against its partner, so its own row is not a 0.
    const auto& other = r == &truth ? *ok[best_k] : truth;
    r->compared_with = other.source;
    r->vs = compare_observed(problem, r->solution.y, other.solution.y, t);
    judge_agreement(*r, t);
  }
}

}  // namespace

double predicted_reference_work(const problem_instance& problem, double horizon) {
  double w = problem.fastest_frequency();
  if (!(w > 0.0) && std::isfinite(problem.period()) && problem.period() > 0.0)
    w = 2.0 * std::numbers::pi / problem.period();
  return 2.0 * problem.dim() * std::max(1.0, w * horizon);
}

truth_table build_truth(const problem_instance& problem, std::span<const double> times, const truth_options& opts) {
  truth_table t;
  t.times.assign(times.begin(), times.end());
  t.agreement_limit = opts.agreement_limit_factor * opts.tol.rtol;
  const bool closed = opts.use_closed_form && problem.has_closed_form();
  if (!closed && !opts.run_references)
    throw std::invalid_argument(fmt::format("problem {}: no closed form and references disabled", problem.name()));
  if (opts.run_references && !closed && !times.empty()) {
    const double predicted = predicted_reference_work(problem, times.back());
    if (predicted > opts.reference_budget) {
      // Not run: nothing to compare, so no truth; the runs are judged on stability alone.
      t.trusted = false;
      t.source = "none";
      t.note = fmt::format(
          "references not run: their predicted work, {:.3g} ({} coordinates x w_max T = {:.3g} rad), is over the "
          "reference budget of {:.3g}",
          predicted, 2 * problem.dim(), problem.fastest_frequency() * times.back(), opts.reference_budget);
      t.y.assign(t.times.size(), std::vector<double>(2 * problem.dim(), std::numeric_limits<double>::quiet_NaN()));
      return t;
    }
  }
  if (opts.run_references) t.references = run_references(problem, times, opts);
  std::vector<reference_check*> ok;
  for (auto& r : t.references)
    if (r.status == "ok") ok.push_back(&r);
  if (closed)
    truth_from_closed_form(problem, t, ok);
  else
    truth_from_references(problem, t, ok);
  if (problem.has_exact_contacts() && !t.times.empty()) {
    const exact_contact_list c = problem.exact_contacts(t.times.back());
    t.contact_count = c.count;
    t.contact_times = c.times;
    t.contact_positions = c.positions;
  }
  if (!std::isfinite(t.pos_scale) || !std::isfinite(t.vel_scale))
    throw std::runtime_error(
        fmt::format("the motion of problem {} overflows: are the parameters in range?", problem.name()));
  return t;
}

run_metrics measure(const problem_instance& problem, const run_result& run, const truth_table& truth) {
  run_metrics m;
  const int dim = problem.dim(), observed_dim = problem.observed_dim();
  auto all_nan = [&] {
    m.err_pos_final = m.err_vel_final = m.err_pos_max = m.err_pos_rms = m.energy_drift = m.energy_err_max = nan;
    m.angmom_drift = m.angmom_err_max = m.contact_count_err = m.contact_time_err = m.contact_pos_err = nan;
    m.constraint_violation_max = nan;
    return m;
  };
  m.contacts = run.contacts;
  m.tunnelled = run.tunnelled;
  m.max_penetration = run.max_penetration;
  if (run.skipped) {
    m.skipped = true;
    m.note = run.stop_reason;
    return all_nan();
  }
  if (!run.stop_reason.empty()) {
    m.failed = true;
    m.note = run.stop_reason;
    return all_nan();
  }
  if (run.non_finite) {
    m.diverged = true;
    m.note = "non-finite state";
    return all_nan();
  }
  if (!truth.trusted) {
    // No truth to measure the error against, but a blow-up needs none: positions past
    // (blowup_factor + 1) times the initial state's extent are the run's own growth (the
    // truth-based test below, |x - x_true| > blowup_factor x amplitude, on a motion that
    // stays within its initial extent; a problem starting at the origin is not judged).
    const double extent = norm_part(problem.observed(problem.initial()), 0, observed_dim);
    double reach = 0.0;
    for (const auto& y : run.sample_y) reach = std::max(reach, norm_part(problem.observed(y), 0, observed_dim));
    all_nan();
    if (extent > 0.0 && !(reach <= (blowup_factor + 1.0) * extent)) {
      m.diverged = true;
      m.note = fmt::format("position {:.3g} exceeds {:g} times the initial extent {:.3g} (no trusted truth here)",
                           reach, blowup_factor + 1.0, extent);
      return m;
    }
    m.failed = true;
    m.note = "no trusted truth: " + truth.note;
    return m;
  }
  if (run.sample_t.size() != truth.times.size())
    throw std::logic_error("measure: the run's samples do not match the truth's times");
  double sum_sq = 0.0, e_max = 0.0, l_max = 0.0;
  for (size_t j = 0; j < truth.times.size(); ++j) {
    if (std::abs(run.sample_t[j] - truth.times[j]) > 1e-12 * std::max(1.0, truth.times[j]))
      throw std::logic_error("measure: a sample time differs from the truth's");
    const double e = norm_diff(problem.observed(run.sample_y[j]), problem.observed(truth.y[j]), 0, observed_dim);
    m.err_pos_max = std::max(m.err_pos_max, e);
    sum_sq += e * e;
    if (problem.has_energy())
      e_max = std::max(e_max, std::abs(problem.energy(run.sample_y[j]) - problem.energy(truth.y[j])));
    if (problem.has_angular_momentum())
      l_max =
          std::max(l_max, std::abs(problem.angular_momentum(run.sample_y[j]) - problem.angular_momentum(truth.y[j])));
  }
  m.err_pos_rms = std::sqrt(sum_sq / static_cast<double>(truth.times.size()));
  m.constraint_violation_max = run.constraint_violation;
  if (!std::isfinite(m.constraint_violation_max)) {
    m.constraint_violation_max = problem.constraint_violation(run.final_y);
    for (const auto& y : run.sample_y)
      m.constraint_violation_max = std::max(m.constraint_violation_max, problem.constraint_violation(y));
  }
  const auto& y_final = run.final_y;
  const auto& y_true = truth.y.back();
  const auto o_final = problem.observed(y_final), o_true = problem.observed(y_true);
  m.err_pos_final = norm_diff(o_final, o_true, 0, observed_dim);
  m.err_vel_final = norm_diff(o_final, o_true, observed_dim, observed_dim);
  if (problem.has_energy()) {
    m.energy_drift = (problem.energy(y_final) - problem.energy(y_true)) / truth.energy_scale;
    m.energy_err_max = e_max / truth.energy_scale;
  } else {
    m.energy_drift = m.energy_err_max = nan;
  }
  if (problem.has_angular_momentum()) {
    m.angmom_drift = (problem.angular_momentum(y_final) - problem.angular_momentum(y_true)) / truth.angmom_scale;
    m.angmom_err_max = l_max / truth.angmom_scale;
  } else {
    m.angmom_drift = m.angmom_err_max = nan;
  }
  // Contacts, matched in order: the k-th of the run against the k-th exact one. NaN where
  // there is nothing to compare (no exact contacts, or none matched).
  const bool exact_contacts = truth.contact_count >= 0;
  m.contact_count_err = exact_contacts ? static_cast<double>(run.contacts - truth.contact_count) : nan;
  const std::size_t matched = std::min(run.contact_times.size(), truth.contact_times.size());
  const std::size_t matched_x = std::min({matched, run.contact_positions.size(), truth.contact_positions.size()});
  m.contact_time_err = matched > 0 ? 0.0 : nan;
  m.contact_pos_err = matched_x > 0 ? 0.0 : nan;
  for (std::size_t k = 0; k < matched; ++k)
    m.contact_time_err = std::max(m.contact_time_err, std::abs(run.contact_times[k] - truth.contact_times[k]));
  for (std::size_t k = 0; k < matched_x; ++k)
    m.contact_pos_err =
        std::max(m.contact_pos_err, norm_diff(run.contact_positions[k], truth.contact_positions[k], 0, dim));
  if (!(m.err_pos_max <= blowup_factor * truth.pos_scale)) {
    m.diverged = true;
    m.note = fmt::format("position error {:.3g} exceeds {:g} times the amplitude", m.err_pos_max, blowup_factor);
  }
  return m;
}

}  // namespace stepbench

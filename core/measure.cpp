#include "core/measure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "core/number.hpp"

namespace stepbench {

double norm(std::span<const double> a, int offset, int dim, std::span<const double> b) {
  double s = 0.0;
  for (int i = 0; i < dim; ++i) {
    const double d = a[offset + i] - (b.empty() ? 0.0 : b[offset + i]);
    s += d * d;
  }
  return std::sqrt(s);
}

double worst_body(std::span<const double> a, int offset, int dim, int body_dim, std::span<const double> b) {
  if (body_dim >= dim) return norm(a, offset, dim, b);
  double worst = 0.0;
  for (int i = 0; i < dim; i += body_dim) {
    const double e = norm(a, offset + i, body_dim, b);
    if (std::isnan(e)) return e;
    worst = std::max(worst, e);
  }
  return worst;
}

agreement compare(std::span<const std::vector<double>> a, std::span<const std::vector<double>> b, int dim, int body_dim,
                  double pos_scale, double vel_scale) {
  agreement out;
  for (size_t j = 0; j < a.size(); ++j) {
    out.pos_rel = std::max(out.pos_rel, worst_body(a[j], 0, dim, body_dim, b[j]) / pos_scale);
    out.vel_rel = std::max(out.vel_rel, worst_body(a[j], dim, dim, body_dim, b[j]) / vel_scale);
  }
  return out;
}

namespace {

// Kinetic energy of [x; v] is E([x; v]) - E([x; 0]) for every problem here (the
// potential depends on x only, the kinetic energy on v only), which needs no
// kinetic-energy hook in the interface. Evaluated at x = 0 for both terms.
double kinetic(const problem_instance& p, std::span<const double> y) {
  std::vector<double> moving(y.begin(), y.end()), rest(y.size(), 0.0);
  for (int i = 0; i < p.dim(); ++i) moving[i] = 0.0;
  return p.energy(moving) - p.energy(rest);
}

// compare() on the observed positions (problem_instance::observed).
agreement compare_observed(const problem_instance& p, std::span<const std::vector<double>> a,
                           std::span<const std::vector<double>> b, const truth_table& t) {
  const auto observed = [&](std::span<const std::vector<double>> ys) {
    std::vector<std::vector<double>> out;
    for (const auto& y : ys) out.push_back(p.observed(y));
    return out;
  };
  return compare(observed(a), observed(b), p.observed_dim(), p.body_dim(), t.pos_scale, t.vel_scale);
}

void set_scales(const problem_instance& p, truth_table& t) {
  const int dim = p.observed_dim(), body = p.body_dim();
  const auto y0 = p.initial();
  const auto o0 = p.observed(y0);
  double xs = worst_body(o0, 0, dim, body), vs = worst_body(o0, dim, dim, body);
  double es = p.has_energy() ? std::max(std::abs(p.energy(y0)), kinetic(p, y0)) : 1.0;
  double ls = p.has_angular_momentum() ? std::abs(p.angular_momentum(y0)) : 0.0;
  for (const auto& y : t.y) {
    const auto o = p.observed(y);
    xs = std::max(xs, worst_body(o, 0, dim, body));
    vs = std::max(vs, worst_body(o, dim, dim, body));
    if (p.has_energy()) es = std::max({es, std::abs(p.energy(y)), kinetic(p, y)});
    if (p.has_angular_momentum()) ls = std::max(ls, std::abs(p.angular_momentum(y)));
  }
  if (p.has_angular_momentum()) t.angmom_scale = ls > 0.0 ? ls : 1.0;
  t.pos_scale = xs > 0.0 ? xs : 1.0;
  t.vel_scale = vs > 0.0 ? vs : 1.0;
  t.energy_scale = es > 0.0 ? es : 1.0;
}

// No trusted truth: every error is NaN, and the note says why.
void distrust(truth_table& t, std::string note, int dim) {
  t.trusted = false;
  t.source = "none";
  t.note = std::move(note);
  t.y.assign(t.times.size(), std::vector<double>(2 * dim, nan));
}

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
    } else {
      try {
        rc.solution = solve_reference(source, sys, times, opts.tol);
      } catch (const std::runtime_error& e) {
        rc.status = "failed";
        rc.reason = e.what();
      }
    }
    out.push_back(std::move(rc));
  }
  return out;
}

// Compares a reference with `source`'s solution `y`, and marks it when it strays beyond the limit.
void check_reference(const problem_instance& p, reference_check& r, const std::string& source,
                     std::span<const std::vector<double>> y, const truth_table& t) {
  r.compared_with = source;
  r.vs = compare_observed(p, r.solution.y, y, t);
  if (r.vs.worst() <= t.agreement_limit) return;
  r.status = "disagrees";
  r.reason = fmt::format("relative error {:.3e} (position) {:.3e} (velocity) exceeds the agreement limit {:.1e}",
                         r.vs.pos_rel, r.vs.vel_rel, t.agreement_limit);
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
  for (auto* r : ok) check_reference(problem, *r, t.source, t.y, t);
}

// The truth from the best-agreeing pair of completed references (on scales from the
// first of them), trusted when they agree within the limit; else no trusted truth.
void truth_from_references(const problem_instance& problem, truth_table& t, const std::vector<reference_check*>& ok) {
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
    // The first failure's reason with the count: what a user can act on.
    std::string first_failure;
    for (const auto& r : t.references)
      if (r.status == "failed") {
        first_failure = r.reason.starts_with(r.source) ? fmt::format(" ({})", r.reason)
                                                       : fmt::format(" ({}: {})", r.source, r.reason);
        break;
      }
    distrust(t,
             ok.size() < 2 ? fmt::format("only {} of {} references completed, and no closed form to check them{}",
                                         ok.size(), t.references.size(), first_failure)
                           : fmt::format("no two references agree within {:.1e} (best pair {} and {}: {:.3e})",
                                         t.agreement_limit, ok[best_i]->source, ok[best_k]->source, best),
             problem.dim());
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
    check_reference(problem, *r, other.source, other.solution.y, t);
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
      distrust(
          t,
          fmt::format("references not run: their predicted work, {:.3g} ({} coordinates x w_max T = {:.3g} "
                      "rad), is over the reference budget of {:.3g}",
                      predicted, 2 * problem.dim(), problem.fastest_frequency() * times.back(), opts.reference_budget),
          problem.dim());
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
  const int dim = problem.dim(), observed_dim = problem.observed_dim(), body = problem.body_dim();
  // The positions the run draws: its state's observed ones, or its own (xpbd's particles).
  const auto drawn = [&](std::size_t j) {
    return run.drawn_samples.empty() ? problem.observed(run.sample_y[j]) : run.drawn_samples[j];
  };
  auto all_nan = [&] {
    m.err_pos_final = m.err_vel_final = m.err_pos_max = m.err_pos_rms = m.energy_drift = m.energy_err_max = nan;
    m.angmom_drift = m.angmom_err_max = m.contact_count_err = m.contact_time_err = m.contact_pos_err = nan;
    m.constraint_violation_max = nan;
    return m;
  };
  m.contacts = run.contacts;
  m.tunnelled = run.tunnelled;
  m.max_penetration = run.max_penetration;
  // A run that stopped short is measured no further: skipped (over the budget), else
  // failed (the solver's reason), else diverged (a non-finite state).
  const bool stopped = run.skipped || !run.stop_reason.empty();
  if (stopped || run.non_finite) {
    (run.skipped ? m.skipped : stopped ? m.failed : m.diverged) = true;
    m.note = stopped ? run.stop_reason : "non-finite state";
    return all_nan();
  }
  if (!truth.trusted) {
    // No truth to measure the error against, but a blow-up needs none: positions past
    // (blowup_factor + 1) times the initial state's extent are the run's own growth (the
    // truth-based test below, |x - x_true| > blowup_factor x amplitude, on a motion that
    // stays within its initial extent; a problem starting at the origin is not judged).
    const double extent = worst_body(problem.observed(problem.initial()), 0, observed_dim, body);
    double reach = 0.0;
    for (std::size_t j = 0; j < run.sample_y.size(); ++j)
      reach = std::max(reach, worst_body(drawn(j), 0, observed_dim, body));
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
  double sum_sq = 0.0;
  for (size_t j = 0; j < truth.times.size(); ++j) {
    if (std::abs(run.sample_t[j] - truth.times[j]) > 1e-12 * std::max(1.0, truth.times[j]))
      throw std::logic_error("measure: a sample time differs from the truth's");
    const double e = worst_body(drawn(j), 0, observed_dim, body, problem.observed(truth.y[j]));
    m.err_pos_max = std::max(m.err_pos_max, e);
    sum_sq += e * e;
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
  const auto o_final = run.drawn_final.empty() ? problem.observed(y_final) : run.drawn_final;
  const auto o_true = problem.observed(y_true);
  m.err_pos_final = worst_body(o_final, 0, observed_dim, body, o_true);
  m.err_vel_final = worst_body(o_final, observed_dim, observed_dim, body, o_true);
  // A conserved quantity q (energy, angular momentum): its signed error at the end and its
  // largest error over the samples, over the truth's scale of it; NaN where there is none.
  const auto conserved = [&](bool has, auto q, double scale, double& drift, double& err_max) {
    drift = err_max = nan;
    if (!has) return;
    double worst = 0.0;
    for (size_t j = 0; j < truth.times.size(); ++j)
      worst = std::max(worst, std::abs(q(run.sample_y[j]) - q(truth.y[j])));
    drift = (q(y_final) - q(y_true)) / scale;
    err_max = worst / scale;
  };
  conserved(
      problem.has_energy(), [&](const auto& y) { return problem.energy(y); }, truth.energy_scale, m.energy_drift,
      m.energy_err_max);
  conserved(
      problem.has_angular_momentum(), [&](const auto& y) { return problem.angular_momentum(y); }, truth.angmom_scale,
      m.angmom_drift, m.angmom_err_max);
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
  // Contact positions are the state's, which is what a problem with contacts observes.
  for (std::size_t k = 0; k < matched_x; ++k)
    m.contact_pos_err =
        std::max(m.contact_pos_err, worst_body(run.contact_positions[k], 0, dim, body, truth.contact_positions[k]));
  if (!(m.err_pos_max <= blowup_factor * truth.pos_scale)) {
    m.diverged = true;
    m.note = fmt::format("position error {:.3g} exceeds {:g} times the amplitude", m.err_pos_max, blowup_factor);
  }
  return m;
}

}  // namespace stepbench

#include "run/stability.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/drive.hpp"
#include "core/number.hpp"
#include "core/system.hpp"
#include "integrators/all.hpp"

namespace stepbench {
namespace {

// ---------------------------------------------------------------------------------
// The test problems. They satisfy the problem contract, so the integrators step them
// through counted_system exactly as they step a study problem, but they are not
// registered as study problems. Each gives its Jacobians (the implicit methods then
// solve a linear problem in one Newton iteration, to round-off) and `size`, the
// quantity whose boundedness is the stability of the motion.

// What they share: N coordinates, a mass (a parameter), Jacobians of fixed size.
template <int N>
struct test_problem {
  static constexpr std::string_view position_unit = "m";
  using vec = Eigen::Matrix<double, N, 1>;
  using jacobian_matrix = Eigen::Matrix<double, N, N>;
  double mass_kg = 1.0;
  int dim() const { return N; }
  double mass() const { return mass_kg; }
  jacobian_matrix make_jacobian() const { return jacobian_matrix::Zero(); }
};

// x'' = -omega^2 x: the force F = -m omega^2 x of a spring with k = m omega^2.
struct oscillator_problem : test_problem<1> {
  static constexpr std::string_view name = "stability_oscillator";
  static constexpr std::string_view description = "undamped oscillator x'' = -omega^2 x (F = -m omega^2 x)";
  static constexpr bool force_depends_on_velocity = false;
  double omega = 1.0;

  static constexpr auto parameters() {
    using p = param<oscillator_problem>;
    return std::array{p{"omega", &oscillator_problem::omega, "rad/s", "angular frequency", positive},
                      p{"mass_kg", &oscillator_problem::mass_kg, "kg", "mass", positive}};
  }
  void force(double, const vec& x, const vec&, vec& f) const { f = (-mass_kg * omega * omega) * x; }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx(0, 0) = -mass_kg * omega * omega;
    dfdv(0, 0) = 0.0;
  }
  phase<vec> initial() const { return {vec(1.0), vec(0.0)}; }
  double horizon() const { return 2.0 * 3.141592653589793 / omega; }  // one period (the runs count steps)
  // The amplitude: sqrt(x^2 + (v / omega)^2), constant along the exact motion.
  double size(const vec& x, const vec& v) const { return std::hypot(x[0], v[0] / omega); }
};

// Pure decay as a game writes it: a damper F = -m lambda v, so v' = -lambda v and x only
// integrates v (x -> x0 + v0 / lambda). It is the velocity equation that must stay
// bounded; x follows it.
struct decay_problem : test_problem<1> {
  static constexpr std::string_view name = "stability_decay";
  static constexpr std::string_view description = "pure damper F = -m lambda v (v' = -lambda v)";
  static constexpr bool force_depends_on_velocity = true;
  double lambda = 1.0;

  static constexpr auto parameters() {
    using p = param<decay_problem>;
    return std::array{p{"lambda", &decay_problem::lambda, "1/s", "decay rate", positive},
                      p{"mass_kg", &decay_problem::mass_kg, "kg", "mass", positive}};
  }
  void force(double, const vec&, const vec& v, vec& f) const { f = (-mass_kg * lambda) * v; }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx(0, 0) = 0.0;
    dfdv(0, 0) = -mass_kg * lambda;
  }
  phase<vec> initial() const { return {vec(0.0), vec(1.0)}; }
  double horizon() const { return 1.0 / lambda; }
  double size(const vec&, const vec& v) const { return std::abs(v[0]); }
};

// The damper with a complex rate lambda = a + i b, on two velocity coordinates:
// F = m L v, L = [[a, -b], [b, a]], so v' = L v is the complex equation v' = lambda v
// with v = v_0 + i v_1. One step of dt maps v to R(dt lambda) v (a complex
// multiplication), and |R| = |v_1| / |v_0|.
struct complex_damper_problem : test_problem<2> {
  static constexpr std::string_view name = "stability_complex_damper";
  static constexpr std::string_view description = "damper with a complex rate, F = m L v, L = [[a, -b], [b, a]]";
  static constexpr bool force_depends_on_velocity = true;
  double rate_re = -1.0;
  double rate_im = 0.0;

  static constexpr auto parameters() {
    using p = param<complex_damper_problem>;
    return std::array{p{"rate_re", &complex_damper_problem::rate_re, "1/s", "real part a of the rate"},
                      p{"rate_im", &complex_damper_problem::rate_im, "1/s", "imaginary part b of the rate"},
                      p{"mass_kg", &complex_damper_problem::mass_kg, "kg", "mass", positive}};
  }
  void force(double, const vec&, const vec& v, vec& f) const {
    f[0] = mass_kg * (rate_re * v[0] - rate_im * v[1]);
    f[1] = mass_kg * (rate_im * v[0] + rate_re * v[1]);
  }
  void jacobian(double, const vec&, const vec&, jacobian_matrix& dfdx, jacobian_matrix& dfdv) const {
    dfdx.setZero();
    dfdv << rate_re, -rate_im, rate_im, rate_re;
    dfdv *= mass_kg;
  }
  phase<vec> initial() const { return {vec::Zero(), vec(1.0, 0.0)}; }
  double horizon() const { return 1.0; }
};

static_assert(problem<oscillator_problem> && has_jacobian<oscillator_problem>);
static_assert(problem<decay_problem> && has_jacobian<decay_problem>);
static_assert(problem<complex_damper_problem> && has_jacobian<complex_damper_problem>);

// ---------------------------------------------------------------------------------
// The compiled steps.

template <class I>
I make_method() {
  if constexpr (adaptive_integrator<I>)
    return I(always_accept_tolerance);
  else
    return I{};
}

// The stepper of method I on problem P, as the drive loop builds it: the method, the
// counted system, the stepper sized once.
template <class I, class P>
struct stepping {
  I method = make_method<I>();
  counted_system<P> sys;
  stepper_t<I, counted_system<P>> stepper{method};

  explicit stepping(const P& p, const typename P::vec& like) : sys(p) { prepare_stepper(stepper, sys, like); }

  // One step of dt: the method's step, or for an adaptive method its attempt, which the
  // tolerance makes an accepted step of exactly dt. Every step starts at t = 0: the test
  // problems do not depend on t.
  void step(step_state<typename P::vec>& s, double dt) {
    if constexpr (adaptive_integrator<I>) {
      const step_attempt a = stepper.try_step(sys, 0.0, s, dt);
      if (!a.accepted || a.dt_taken != dt)
        throw std::logic_error(fmt::format("{}: an attempt of dt = {:g} was not accepted at tolerance {:g}", I::name,
                                           dt, always_accept_tolerance));
    } else {
      stepper.step(sys, 0.0, s, dt);
    }
  }
};

// One step of dt from (x, v), with a fresh stepper (an implicit method factors its
// Newton matrix for this problem and dt). False when the step fails (an implicit
// method's Newton iteration finds no solution, as at a pole of its R), with the
// method's message in `why` when given.
template <class I, class P>
bool one_step(const P& p, step_state<typename P::vec>& s, double dt, std::string* why = nullptr) {
  stepping<I, P> st(p, s.x);
  try {
    st.step(s, dt);
  } catch (const std::runtime_error& e) {
    if (why) *why = e.what();
    return false;
  }
  return true;
}

// M(y): its columns are one step of dt = y (omega = lambda = 1) from [x; v] = [1; 0]
// and [0; 1]. Every step here is linear in the state (the implicit ones up to their
// Newton tolerance, which on a linear problem with its exact Jacobian is round-off).
// NaN entries when the step fails.
template <class I, class P>
Eigen::Matrix2d amplification(const P& p, double dt, std::string* why = nullptr) {
  using vec = typename P::vec;
  Eigen::Matrix2d m;
  for (int c = 0; c < 2; ++c) {
    step_state<vec> s{vec(c == 0 ? 1.0 : 0.0), vec(c == 1 ? 1.0 : 0.0), vec::Zero(), false};
    if (!one_step<I>(p, s, dt, why)) return Eigen::Matrix2d::Constant(nan);
    m(0, c) = s.x[0];
    m(1, c) = s.v[0];
  }
  return m;
}

enum class verdict { stable, unstable, step_failed };

// One long run of dt from the problem's initial state (stability_settings says how it
// is judged). The stepper is stepped directly in a loop (the drive loop's advance stage
// without its recording), so that the size is seen after every step.
template <class I, class P>
verdict long_run(const P& p, double dt, const stability_settings& set, std::string& why) {
  auto s = start_state(p);
  stepping<I, P> st(p, s.x);
  const double blowup = set.blowup_factor * p.size(s.x, s.v), decayed = set.decay_floor * p.size(s.x, s.v);
  const long half = set.run_steps / 2;
  double first = p.size(s.x, s.v), second = 0.0;
  for (long n = 1; n <= set.run_steps; ++n) {
    try {
      st.step(s, dt);
    } catch (const std::runtime_error& e) {
      why = e.what();
      return verdict::step_failed;
    }
    const double size = p.size(s.x, s.v);
    if (!(size <= blowup)) return verdict::unstable;
    if (size < decayed) return verdict::stable;
    double& envelope = n <= half ? first : second;
    envelope = std::max(envelope, size);
  }
  return second > set.envelope_growth * first ? verdict::unstable : verdict::stable;
}

// ---------------------------------------------------------------------------------
// The limits.

std::vector<double> scan_grid(const stability_settings& s) {
  std::vector<double> ys;
  const int n = static_cast<int>(std::lround(s.per_decade * std::log10(s.y_max / s.y_min)));
  for (int k = 0; k <= n; ++k) ys.push_back(s.y_min * std::pow(s.y_max / s.y_min, static_cast<double>(k) / n));
  ys.push_back(s.y_unconditional);
  return ys;
}

// Bisection between a stable lo and an unstable hi to hi - lo <= rtol hi.
template <class Stable>
std::pair<double, double> bisect(double lo, double hi, double rtol, Stable&& stable) {
  while (hi - lo > rtol * hi) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return {lo, hi};
}

// One method's limit being found: the result so far, and the method's message at the
// first failed step.
struct limit_search {
  stability_limit out;
  std::string why, first_why;
  void failed_at(double y) {
    if (!(y >= out.step_failed_at)) first_why = why;
    out.step_failed_at = std::fmin(out.step_failed_at, y);
  }
};

// (a) From the amplification matrix: rho(M(y)) - 1 against the allowance rho_tol, over
// the scan grid, then bisected to the first change from stable to unstable. Sets
// out.theory, or out.unstable_for_all_dt or out.unconditionally_stable; false when the
// verdict ends here (the step fails, or rho is too close to the allowance to classify).
template <class I, class P>
bool theory_limit(const P& p, const stability_settings& s, limit_search& f) {
  stability_limit& out = f.out;
  const auto excess = [&](double y) { return spectral_radius(amplification<I>(p, y, &f.why)) - 1.0; };
  const auto judge = [&](double y) {
    const double e = excess(y);
    if (std::isnan(e)) return f.failed_at(y), verdict::step_failed;
    return e <= s.rho_tol ? verdict::stable : verdict::unstable;
  };
  const auto ys = scan_grid(s);
  const double e0 = excess(ys.front());
  if (std::isnan(e0)) {
    f.failed_at(ys.front());
    out.note = fmt::format("the step fails at y = {:g} ({})", ys.front(), f.why);
    return false;
  }
  if (e0 > s.rho_tol) {
    if (!(e0 > s.clear_factor * s.rho_tol)) {
      out.note =
          fmt::format("rho - 1 = {:.3g} at y = {:g}: too close to the round-off allowance to classify", e0, ys.front());
      return false;
    }
    out.unstable_for_all_dt = true;
    return true;
  }
  double last_stable = ys.front();
  int failures = 0;
  for (std::size_t k = 1; k < ys.size() && std::isnan(out.theory); ++k) {
    const verdict v = judge(ys[k]);
    if (v == verdict::step_failed) {
      ++failures;
    } else if (v == verdict::stable) {
      last_stable = ys[k];
    } else {
      const auto [lo, hi] =
          bisect(last_stable, ys[k], s.root_rtol, [&](double y) { return judge(y) == verdict::stable; });
      out.theory = 0.5 * (lo + hi);
    }
  }
  if (!std::isnan(out.theory)) return true;
  if (failures == 0) {
    out.unconditionally_stable = true;
    return true;
  }
  // Stable wherever the step exists: no verdict on the rest.
  out.note = fmt::format(
      "stable at every y of the scan where the step exists; the step fails at {} of {} "
      "scan points, from y = {:.4g} ({})",
      failures, ys.size(), out.step_failed_at, f.first_why);
  return false;
}

// (b) From long runs of the compiled step: confirms a verdict of (a), or measures the
// limit by walking from run_y_start to the first change of verdict and bisecting.
template <class I, class P>
void measured_limit(const P& p, const stability_settings& s, limit_search& f) {
  stability_limit& out = f.out;
  const auto run = [&](double y) {
    const verdict v = long_run<I>(p, y, s, f.why);
    if (v == verdict::step_failed) f.failed_at(y);
    return v;
  };
  const auto words = [&](verdict v) {
    return v == verdict::stable ? "bounded" : v == verdict::unstable ? "grows" : "the step fails";
  };
  if (out.unstable_for_all_dt) {
    const verdict v = run(s.confirm_y);
    out.run_confirms = v == verdict::unstable;
    out.note = fmt::format("{} steps at y = {:g}: {}", s.run_steps, s.confirm_y, words(v));
    return;
  }
  if (out.unconditionally_stable) {
    const verdict at_max = run(s.y_max), at_unconditional = run(s.y_unconditional);
    out.run_confirms = at_max == verdict::stable && at_unconditional == verdict::stable;
    out.note = fmt::format("{} steps at y = {:g}: {}; at y = {:g}: {}", s.run_steps, s.y_max, words(at_max),
                           s.y_unconditional, words(at_unconditional));
    return;
  }
  const auto bounded = [&](double y) { return run(y) == verdict::stable; };
  const double factor = std::pow(10.0, 1.0 / s.run_per_decade);
  double lo, hi;
  if (bounded(s.run_y_start)) {
    for (lo = s.run_y_start, hi = lo * factor; hi <= s.y_unconditional && bounded(hi); lo = hi, hi *= factor) {
    }
  } else {
    for (hi = s.run_y_start, lo = hi / factor; lo >= s.y_min && !bounded(lo); hi = lo, lo /= factor) {
    }
  }
  if (lo >= s.y_min && hi <= s.y_unconditional) {
    const auto [a, b] = bisect(lo, hi, s.run_rtol, bounded);
    out.measured = 0.5 * (a + b);
    out.run_confirms = std::abs(out.rel_difference()) <= s.agreement;
    out.note = fmt::format("{} steps: bounded at y = {:.7g}, grows at {:.7g}", s.run_steps, a, b);
    // A run shows growth only when rho^(run_steps / 2) exceeds envelope_growth: a weak
    // instability (rho - 1 between the allowance rho_tol and that sensitivity, as Verner's
    // 7(6) step has on the oscillator, |R(iy)| - 1 ~ y^8) leaves it bounded beyond the
    // theory's limit. The runs then agree with the theory when its excess at the largest
    // y they found bounded is below their sensitivity, and the note says so.
    if (!out.run_confirms && out.measured > out.theory) {
      const double sensitivity = std::pow(s.envelope_growth, 2.0 / static_cast<double>(s.run_steps)) - 1.0;
      const double excess = spectral_radius(amplification<I>(p, a, &f.why)) - 1.0;
      if (excess < sensitivity) {
        out.run_confirms = true;
        out.note += fmt::format("; rho - 1 = {:.2g} a step there, below what {} steps can show ({:.2g})", excess,
                                s.run_steps, sensitivity);
      }
    }
  } else {
    out.note = fmt::format("{} steps: no change of verdict between y = {:g} and {:g}", s.run_steps, s.y_min,
                           s.y_unconditional);
  }
}

template <class I, class P>
stability_limit limit_of(const P& p, stability_test test, const stability_settings& s) {
  limit_search f{{std::string(I::name), test, nan, nan, false, false, false, nan, {}}, {}, {}};
  if (theory_limit<I>(p, s, f)) measured_limit<I>(p, s, f);
  return f.out;
}

// ---------------------------------------------------------------------------------
// The regions: one step of dt = 1 on the complex damper with rate z, from v = (1, 0).

template <class I>
std::vector<double> region_of(const std::vector<double>& re, const std::vector<double>& im) {
  std::vector<double> out;
  out.reserve(re.size() * im.size());
  complex_damper_problem p;
  for (double b : im)
    for (double a : re) {
      p.rate_re = a;
      p.rate_im = b;
      auto s = start_state(p);
      out.push_back(one_step<I>(p, s, 1.0) ? s.v.norm() : nan);
    }
  return out;
}

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> out;
  for (int k = 0; k < n; ++k) out.push_back(k + 1 == n ? b : a + (b - a) * k / (n - 1));
  return out;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string_view to_string(stability_test t) { return t == stability_test::oscillator ? "oscillator" : "decay"; }

double spectral_radius(const Eigen::Matrix2d& m) {
  // Eigenvalues T/2 +- sqrt(T^2/4 - D). The discriminant is formed as ((a - d)/2)^2 + b c,
  // which does not cancel when the eigenvalues are close to each other (on decay, 1 and
  // R near 1); a complex pair has modulus sqrt(D).
  const double half_trace = 0.5 * (m(0, 0) + m(1, 1));
  const double half_diff = 0.5 * (m(0, 0) - m(1, 1));
  const double disc = half_diff * half_diff + m(0, 1) * m(1, 0);
  if (disc >= 0.0) return std::abs(half_trace) + std::sqrt(disc);
  return std::sqrt(m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0));
}

Eigen::Matrix2d amplification_matrix(std::string_view integrator, stability_test test, double y) {
  std::optional<Eigen::Matrix2d> m;
  for_each_type(all_integrators{}, [&]<class I>() {
    if (I::name == integrator)
      m = test == stability_test::oscillator ? amplification<I>(oscillator_problem{}, y)
                                             : amplification<I>(decay_problem{}, y);
  });
  if (!m) throw std::invalid_argument(fmt::format("unknown integrator '{}'", integrator));
  return *m;
}

const std::vector<double>& stability_regions::of(std::string_view integrator) const {
  for (std::size_t k = 0; k < integrators.size(); ++k)
    if (integrators[k] == integrator) return abs_r[k];
  throw std::out_of_range(fmt::format("no stability region for '{}'", integrator));
}

stability_data compute_stability(const stability_settings& settings) {
  stability_data out;
  out.settings = settings;
  auto start = std::chrono::steady_clock::now();
  for_each_type(all_integrators{}, [&]<class I>() {
    for (auto test : {stability_test::oscillator, stability_test::decay})
      out.limits.push_back(test == stability_test::oscillator ? limit_of<I>(oscillator_problem{}, test, settings)
                                                              : limit_of<I>(decay_problem{}, test, settings));
  });
  out.limits_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  auto& r = out.regions;
  r.re = linspace(settings.re_min, settings.re_max, settings.re_count);
  r.im = linspace(settings.im_min, settings.im_max, settings.im_count);
  for_each_type(all_integrators{}, [&]<class I>() {
    r.integrators.emplace_back(I::name);
    r.abs_r.push_back(region_of<I>(r.re, r.im));
  });
  out.regions_seconds = seconds_since(start);
  return out;
}

}  // namespace stepbench

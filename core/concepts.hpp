#pragma once
// What a problem and an integrator are. These are compile-time contracts: the step
// loop is instantiated per (problem, integrator) pair and inlines the force model.
// Type erasure happens only in core/registry.hpp.
#include <array>
#include <cmath>
#include <concepts>
#include <string>
#include <string_view>

namespace stepbench {

// A named, user-settable parameter (`--set name=value`), bound to a data member.
template <class P>
struct param {
  std::string_view name;
  double P::*member;
  std::string_view unit;
  std::string_view description;
};

// The state an integrator advances. `f` caches the force at (t, x, v) when `f_current`
// is true, so a method whose last stage lands on the new state (velocity Verlet with a
// velocity-independent force) pays one force evaluation per step, not two. Anything
// that changes x or v from outside the integrator (an event, a reset) must clear
// `f_current`.
template <class Vec>
struct step_state {
  Vec x;
  Vec v;
  Vec f;
  bool f_current = false;
};

// Position and velocity at one time: what closed forms and references return.
template <class Vec>
struct phase {
  Vec x;
  Vec v;
};

// A problem: the forces of one scene and nothing else (no general physics engine).
// The integrators see F(t, x, v) and m, as in the lecture.
template <class P>
concept problem = requires(const P& p, double t, const typename P::vec& x) {
  { P::name } -> std::convertible_to<std::string_view>;
  { P::description } -> std::convertible_to<std::string_view>;
  { P::dim } -> std::convertible_to<int>;
  { P::position_unit } -> std::convertible_to<std::string_view>;  // "m", or "rad" for an angle
  { P::force_depends_on_velocity } -> std::convertible_to<bool>;
  { P::parameters() };
  { p.mass() } -> std::convertible_to<double>;
  { p.force(t, x, x) } -> std::convertible_to<typename P::vec>;
  { p.initial() } -> std::same_as<phase<typename P::vec>>;
  { p.horizon() } -> std::convertible_to<double>;
  { p.validate() } -> std::convertible_to<std::string>;  // empty when the parameters are valid
};

template <class P>
concept has_closed_form = requires(const P& p, double t) {
  { p.exact(t) } -> std::same_as<phase<typename P::vec>>;
};

template <class P>
concept has_energy = requires(const P& p, const typename P::vec& x) {
  { p.energy(x, x) } -> std::convertible_to<double>;
};

// A fixed-step integrator: a small value type with its name, its order and one step.
template <class I>
concept integrator = requires {
  { I::name } -> std::convertible_to<std::string_view>;
  { I::order } -> std::convertible_to<int>;
  { I::description } -> std::convertible_to<std::string_view>;
};

// 1 / m. The integrators work with the force and fold 1 / m into their step
// coefficients (v += (h / m) F, the momentum form's own idea): one multiplication less
// on each stage's dependency chain (v -> F -> v), which is what bounds a step's latency,
// and no division at all. The drive loop's system computes 1 / m once per run
// (counted_system::inverse_mass); a bare problem falls back to dividing here.
template <class Sys>
inline double inverse_mass(const Sys& sys) {
  if constexpr (requires { sys.inverse_mass(); })
    return sys.inverse_mass();
  else
    return 1.0 / sys.mass();
}

// F at the state's (x, v), computed once and cached in the state.
template <class Sys, class Vec>
inline const Vec& current_force(const Sys& sys, double t, step_state<Vec>& s) {
  if (!s.f_current) {
    s.f = sys.force(t, s.x, s.v);
    s.f_current = true;
  }
  return s.f;
}

// Parameter checks shared by the problems; each returns "" or a one-line reason.
inline std::string require_positive(std::string_view name, double value) {
  if (std::isfinite(value) && value > 0.0) return {};
  return std::string(name) + " must be a positive finite number";
}
inline std::string require_finite(std::string_view name, double value) {
  if (std::isfinite(value)) return {};
  return std::string(name) + " must be finite";
}

}  // namespace stepbench

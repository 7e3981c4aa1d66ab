#pragma once
// What a problem and an integrator are. These are compile-time contracts: the step
// loop is instantiated per (problem, integrator) pair and inlines the force model.
// Type erasure happens only in the registry (problem_model<P> in registry/problem_model.hpp,
// compiled once per problem), outside every loop.
//
// The integrator categories follow Boost.Odeint's: a stepper advances by a given dt;
// an adaptive stepper tries a step, estimates its error and proposes the next dt (and
// may interpolate inside the step it took: dense output). What a method needs or offers
// beyond that (a Jacobian, symplecticity, reuse of the last force) is declared in its
// `capabilities`, which the registry and the study file report.
#include <Eigen/Core>
#include <concepts>
#include <string>
#include <string_view>
#include <vector>

#include "core/parameter.hpp"

namespace stepbench {

// The state an integrator advances. `f` caches the force at (t, x, v) when `f_current`
// is true, so a method whose last stage lands on the new state (velocity Verlet with a
// velocity-independent force) pays one force evaluation per step, not two. Anything
// that changes x or v from outside the integrator (a contact, a reset) must clear
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

// [x; v] in one plain vector: a state as the registry, the references and the study file hold it.
template <class Vec>
std::vector<double> stacked(const Vec& x, const Vec& v) {
  std::vector<double> y(x.data(), x.data() + x.size());
  y.insert(y.end(), v.data(), v.data() + v.size());
  return y;
}
template <class Vec>
std::vector<double> stacked(const phase<Vec>& s) {
  return stacked(s.x, s.v);
}

// A problem: the forces of one scene and nothing else (no general physics engine).
// The integrators see F(t, x, v) and a scalar mass m, as in the lecture. `vec` is an
// Eigen column vector, fixed-size (the step inlines to scalar code) or Eigen::VectorXd
// for scenes sized at run time (`dim()` then reads a parameter). `force` writes into
// `f`, which has dim() entries: it must not allocate, so that no step does.
template <class P>
concept problem = requires(const P& p, double t, const typename P::vec& x, typename P::vec& f) {
  { P::name } -> std::convertible_to<std::string_view>;
  { P::description } -> std::convertible_to<std::string_view>;
  { P::position_unit } -> std::convertible_to<std::string_view>;  // "m", or "rad" for an angle
  { P::force_depends_on_velocity } -> std::convertible_to<bool>;
  {P::parameters()};  // declared once: core/parameter.hpp (validate(p) derives from it)
  { p.dim() } -> std::convertible_to<int>;
  { p.mass() } -> std::convertible_to<double>;
  {p.force(t, x, x, f)};
  { p.initial() } -> std::same_as<phase<typename P::vec>>;
  { p.horizon() } -> std::convertible_to<double>;
};

template <class P>
concept has_closed_form = requires(const P& p, double t) {
  { p.exact(t) } -> std::same_as<phase<typename P::vec>>;
};

template <class P>
concept has_energy = requires(const P& p, const typename P::vec& x) {
  { p.energy(x, x) } -> std::convertible_to<double>;
};

// What one pass of a problem's contact resolution did (resolve_contacts, below).
struct contact_outcome {
  int resolved = 0;      // contacts whose response was applied (approaching, penetrated or touching)
  int tunnelled = 0;     // contacts found deeper than the problem's stated tunnelling depth
  double depth = 0.0;    // the deepest penetration found, >= 0
  bool changed = false;  // the state was changed (a response, or a body moved back to a surface)
};

// A problem with contacts (a ground plane, walls, other bodies): the drive loop, not the
// integrator, handles them (core/drive.hpp). contact_gap is the smallest signed distance
// of the contacts (< 0: penetrated); resolve_contacts applies the lecture's response
// (on collisions: move back to the surface, v_b = (1 - k_f) v_t - k_r v_n) to every
// penetrated or touching contact that approaches, moves every penetrated body back to
// its surface, and says what it did; locate_contacts chooses the mode: false
// `end_of_step` (what games do: resolve after the step), true `locate` (find the contact
// time inside the step, resolve there, finish the step).
template <class P>
concept has_contacts = requires(const P& p, double t, typename P::vec& x) {
  { p.contact_gap(t, x, x) } -> std::convertible_to<double>;
  { p.resolve_contacts(t, x, x) } -> std::same_as<contact_outcome>;
  { p.locate_contacts() } -> std::convertible_to<bool>;
};

// A problem with Coulomb friction along its one coordinate, a set-valued force: while
// the body slides, mu_k |F_n| against the motion; at rest, any force up to mu_s |F_n|
// (the friction cone). As a function of v the law has no value at rest that a Newton
// iteration can find a root through, so the implicit methods resolve it as engines do
// (Box2D, PhysX and Bullet clamp the friction impulse to mu |normal impulse|; implicit
// Euler with the set-valued law is Moreau-Jean time stepping: Moreau, "Unilateral
// contact and dry friction in finite freedom dynamics", 1988; Jean, "The non-smooth
// contact dynamics method", 1999): the step with the smooth forces, then the friction
// that step needs, clamped to the cone (integrators/implicit_newton.hpp). The problem's
// `force` stays the lecture's law, which the explicit methods use.
struct friction_limits {
  double static_max = 0.0;  // mu_s |F_n| [N]: the most friction can hold at rest
  double kinetic = 0.0;     // mu_k |F_n| [N]: friction while sliding
};
template <class P>
concept has_set_valued_friction = requires(const P& p, double t, const typename P::vec& x, typename P::vec& f) {
  {p.smooth_force(t, x, x, f)};  // every force but friction
  { p.friction(t, x) } -> std::same_as<friction_limits>;
};

// A problem that can say what happened in its scene at a state (an orbit collapsed into
// the centre, a body sunk through the ground), for every method alike: where a run stops
// on a solver's failure, its recorded reason opens with this report, then the solver's
// symptom (core/drive.hpp).
template <class P>
concept has_scene_report = requires(const P& p, double t, const typename P::vec& x) {
  { p.scene_report(t, x, x) } -> std::convertible_to<std::string>;
};

// A problem whose exact contacts are known (bouncing_ball: the bounce sequence;
// bouncing_balls: the event-driven simulation): the contacts with t <= t_end. `positions`
// (the state's position at each contact) may be empty when there are too many bodies for
// contact-by-contact matching to mean anything; `count` is always the number of contacts.
struct exact_contact_list {
  long count = 0;
  std::vector<double> times;
  std::vector<std::vector<double>> positions;
};
template <class P>
concept has_exact_contacts = requires(const P& p, double t) {
  { p.exact_contacts(t) } -> std::same_as<exact_contact_list>;
};

// A problem with an angular momentum about a fixed point (kepler): recorded with its
// error beside the energy's.
template <class P>
concept has_angular_momentum = requires(const P& p, const typename P::vec& x) {
  { p.angular_momentum(x, x) } -> std::convertible_to<double>;
};

// A problem whose coordinates are not the positions its errors are measured on
// (n_pendulum: link angles, measured on the bobs' Cartesian positions): `observe` writes
// those positions and their velocities, observed_dim() entries each, from a state.
template <class P>
concept has_observed_positions = requires(const P& p, const typename P::vec& x, Eigen::VectorXd& out) {
  { p.observed_dim() } -> std::convertible_to<int>;
  {p.observe(x, x, out, out)};
};

// A scene of several bodies (n_pendulum's bobs, spring_chain's masses, bouncing_balls):
// its observed positions are blocks of body_dim() coordinates, one block a body, and a
// position error is the largest of any one body's Euclidean error (what a player sees:
// the body furthest off), not the norm of the stacked vector, which grows like sqrt(N)
// on N bodies equally off. A problem without it is one body.
template <class P>
concept has_bodies = requires(const P& p) {
  { p.body_dim() } -> std::convertible_to<int>;
};

// A problem with a period (pendulum, kepler): the long-run energy study counts its
// horizon in periods.
template <class P>
concept has_period = requires(const P& p) {
  { p.period() } -> std::convertible_to<double>;
};

// A problem may give the force Jacobians dF/dx and dF/dv itself (in a matrix type of
// its choosing: dense for a few coordinates, banded for a chain); otherwise the
// implicit methods get forward differences, whose force evaluations are counted.
template <class P>
concept has_jacobian = requires(const P& p, double t, const typename P::vec& x, typename P::jacobian_matrix& j) {
  {p.jacobian(t, x, x, j, j)};
  { p.make_jacobian() } -> std::same_as<typename P::jacobian_matrix>;  // zeroed, of the right shape
};

// What a method needs and offers, beyond advancing the state. Reported by `stepbench
// list` and recorded in the study file.
struct capabilities {
  bool symplectic = false;         // preserves the symplectic form (bounded energy error on oscillators)
  bool reuses_last_force = false;  // the last stage's force is the next step's first (FSAL)
  bool needs_jacobian = false;     // solves with dF/dx, dF/dv (implicit methods)
  bool error_estimate = false;     // estimates its local error (adaptive methods)
  bool dense_output = false;       // interpolates inside its last step
  // One constraint pass a step on its own particles (XPBD small steps, Macklin et al.
  // 2019): its dt ladder at a frame is a substep count, judged as such by the verdict.
  bool small_steps = false;
};

// The work an integrator reports beyond force evaluations (implicit and adaptive
// methods), counted by the system it steps (core/system.hpp).
struct work_counters {
  long force_evals = 0;
  long jacobian_evals = 0;
  long newton_iterations = 0;
  long linear_solves = 0;
};

namespace detail {
// A stand-in system, only to check in the concepts below that a step compiles.
struct probe_system {
  using vec = Eigen::Matrix<double, 1, 1>;
  using jacobian_matrix = Eigen::Matrix<double, 1, 1>;
  static constexpr bool force_depends_on_velocity = true;
  mutable work_counters work;
  int dim() const;
  double mass() const;
  double inverse_mass() const;
  void force(double, const vec&, const vec&, vec&) const;
  jacobian_matrix make_jacobian() const;
  void jacobian(double, const vec&, const vec&, jacobian_matrix&, jacobian_matrix&) const;
};
}  // namespace detail

// Sizes workspace vectors like the state and zeroes them, once per run, so that no
// step allocates (for fixed-size vectors it only initialises them).
template <class Vec, class... More>
inline void size_like(const Vec& like, Vec& first, More&... more) {
  first.setZero(like.size());
  (more.setZero(like.size()), ...);
}

// A method that needs scratch space (stage vectors, a Jacobian, a controller's memory)
// declares `template <class Sys> struct stepper` (Sys the system it steps, with its
// `vec` and `jacobian_matrix` types), constructed from the method and sized once per
// run by `resize(sys, like)`; it holds the space as members and has the step, as
// Odeint's steppers keep theirs, sized once by their resizer. A method without scratch
// space has the step itself.
template <class I, class Sys>
struct stepper_of {
  using type = I;
};
template <class I, class Sys>
requires requires { typename I::template stepper<Sys>; }
struct stepper_of<I, Sys> {
  using type = typename I::template stepper<Sys>;
};
// The object that steps `Sys`'s states for method I: constructed from the method, then
// sized once with prepare_stepper.
template <class I, class Sys>
using stepper_t = typename stepper_of<I, Sys>::type;

template <class S, class Sys>
inline void prepare_stepper(S& stepper, const Sys& sys, const typename Sys::vec& like) {
  if constexpr (requires { stepper.resize(sys, like); }) stepper.resize(sys, like);
}

// What every integrator declares: its name, its order, a description and its capabilities.
template <class I>
concept described_method = requires {
  { I::name } -> std::convertible_to<std::string_view>;
  { I::order } -> std::convertible_to<int>;
  { I::description } -> std::convertible_to<std::string_view>;
  { I::traits } -> std::convertible_to<capabilities>;
};

// A fixed-step integrator (Odeint's "stepper"): a small value type with its name, its
// order, its capabilities and one step of a given dt.
template <class I>
concept integrator = described_method<I> &&
    requires(const I& i, const detail::probe_system& sys, step_state<detail::probe_system::vec>& s) {
  {stepper_t<I, detail::probe_system>(i).step(sys, 0.0, s, 0.1)};
};

// The outcome of one attempt of an adaptive step.
struct step_attempt {
  bool accepted = false;
  double dt_taken = 0.0;  // the dt of an accepted step
  double dt_next = 0.0;   // the controller's proposal for the next attempt
};

// An adaptive integrator (Odeint's "controlled stepper"): constructed with a tolerance,
// it tries a step of at most dt, accepts or rejects it by its error estimate, and
// proposes the next dt. On rejection the state is unchanged. `initial_dt` proposes the
// first step of a run.
template <class I>
concept adaptive_integrator = described_method<I> &&
    requires(const I& i, const detail::probe_system& sys, step_state<detail::probe_system::vec>& s) {
  {I(1e-6)};
  { I::force_evals_per_step } -> std::convertible_to<int>;  // for the step budget
  { stepper_t<I, detail::probe_system>(i).initial_dt(sys, 0.0, s, 1.0) } -> std::convertible_to<double>;
  { stepper_t<I, detail::probe_system>(i).try_step(sys, 0.0, s, 0.1) } -> std::same_as<step_attempt>;
};

// An adaptive integrator that interpolates inside its last accepted step (Odeint's
// "dense-output stepper"): the drive loop records the sample times from the
// interpolant instead of shortening steps to land on them.
template <class I>
concept dense_output_integrator = adaptive_integrator<I> && requires(const I& i, detail::probe_system::vec& x) {
  {stepper_t<I, detail::probe_system>(i).interpolate(0.5, x, x)};
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
    sys.force(t, s.x, s.v, s.f);
    s.f_current = true;
  }
  return s.f;
}

}  // namespace stepbench

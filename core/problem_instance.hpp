#pragma once
// A problem with its parameters, type-erased: what the application (sweep, commands,
// benchmark) holds. problem_model<P> (registry/problem_model.hpp) implements it once per
// problem type, in that problem's own unit, and registry/registry.cpp makes it by name;
// every call below dispatches to code instantiated for that type, so no step loop makes
// a virtual call.
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/method.hpp"
#include "core/parameter.hpp"
#include "references/reference.hpp"

namespace stepbench {

struct loop_config;  // core/game_loop.hpp
struct loop_result;

class problem_instance {
 public:
  virtual ~problem_instance() = default;
  virtual std::string_view name() const = 0;
  virtual std::string_view description() const = 0;
  virtual int dim() const = 0;
  virtual std::string_view position_unit() const = 0;
  // The declared parameters (core/parameter.hpp) with their values, in declaration order.
  virtual std::vector<param_value> params() const = 0;
  // Sets a parameter; throws std::invalid_argument naming an unknown parameter and
  // listing the known ones. The value is checked by validate(), not here.
  virtual void set(std::string_view param, double value) = 0;
  // "" when every parameter is admitted and the scene is consistent, else the reason.
  virtual std::string validate() const = 0;
  virtual double horizon() const = 0;
  virtual bool has_closed_form() const = 0;
  virtual bool has_energy() const = 0;
  virtual bool has_jacobian() const = 0;
  // [x; v] of the closed form at t; throws std::logic_error without a closed form.
  virtual std::vector<double> exact(double t) const = 0;
  // Total energy of [x; v]; NaN when the problem defines none.
  virtual double energy(std::span<const double> y) const = 0;
  virtual std::vector<double> initial() const = 0;  // [x0; v0]
  // Angular momentum of [x; v] about the problem's fixed point; NaN when it has none.
  virtual bool has_angular_momentum() const = 0;
  virtual double angular_momentum(std::span<const double> y) const = 0;
  // The positions errors are measured on, and their velocities, [X; V] of a state
  // [x; v], observed_dim() entries each: the state itself, except for a problem whose
  // coordinates are not positions (core/concepts.hpp's has_observed_positions).
  virtual int observed_dim() const = 0;
  // The coordinates of one body in the observed positions (core/concepts.hpp's
  // has_bodies): a position error is the largest of any one body's; observed_dim() for a
  // problem of one body.
  virtual int body_dim() const = 0;
  // max_j |C_j| / L_j of the state's constraint view (core/constraints.hpp): 0 for rigid
  // links in generalized coordinates, a compliant constraint's stretch; NaN without a view.
  virtual double constraint_violation(std::span<const double> y) const = 0;
  virtual std::vector<double> observed(std::span<const double> y) const = 0;
  // The period of the motion (pendulum, kepler); NaN when it has none.
  virtual double period() const = 0;
  // Contacts: "none", "end_of_step" or "locate" (core/concepts.hpp's has_contacts).
  virtual std::string_view contact_mode() const = 0;
  // The exact contacts up to t_end; throws std::logic_error for a problem without them.
  virtual bool has_exact_contacts() const = 0;
  virtual exact_contact_list exact_contacts(double t_end) const = 0;
  // The fastest natural frequency at the start (rad/s), a Gershgorin bound from the force
  // Jacobian (core/first_order.hpp fastest_frequency); 0 for a problem without one.
  virtual double fastest_frequency() const = 0;
  // The first-order form y' = [v; F/m] for the reference solvers.
  virtual ode_system ode() const = 0;

  // The methods that run on this problem, ours first, in registry order.
  virtual std::vector<method_info> methods() const = 0;
  // Runs `method` at `param` (dt or tolerance) to `horizon`, recording [x; v] at
  // `times` (increasing, in (0, horizon]). A method that cannot complete the run
  // returns with `failure` set; an unknown method throws std::invalid_argument.
  virtual run_result run(std::string_view method, double param, double horizon, std::span<const double> times,
                         const run_limits& limits = {}) const = 0;
  // The same run, prepared once (the record plan) and performed whole by each call of
  // the returned function, for timing. Returns a value of the final state to keep.
  virtual std::function<double()> timed_run(std::string_view method, double param, double horizon,
                                            std::span<const double> times, const run_limits& limits = {}) const = 0;
  // The game loop `config` drives with our fixed-step integrator `method` (core/game_loop.hpp),
  // simulated whole in code instantiated for the pair. Throws std::invalid_argument for
  // a method that is not one of our fixed-step integrators, or a config that
  // loop_config_error refuses.
  virtual loop_result loop(std::string_view method, const loop_config& config) const = 0;
};

}  // namespace stepbench

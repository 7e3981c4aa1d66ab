#pragma once
// The registry's type erasure: problem_model<P>, the problem_instance of a problem type,
// over its table of methods (registry/method_table.hpp). Included by the problem units
// CMake generates from registry/problem_unit.cpp.in, one per problem.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string_view>

#include "core/constraints.hpp"
#include "core/first_order.hpp"
#include "core/game_loop.hpp"
#include "core/number.hpp"
#include "registry/method_table.hpp"
#include "registry/plugin_adapter.hpp"
#include "registry/plugins.hpp"
#include "registry/registry.hpp"

namespace stepbench::registry_detail {

[[noreturn]] inline void not_applicable(std::string_view method, std::string_view problem) {
  throw std::invalid_argument(fmt::format("method {} does not run on problem {}", method, problem));
}

template <problem P>
class problem_model final : public problem_instance {
  using vec = typename P::vec;
  P p_;

  vec unflatten(std::span<const double> y, int offset) const {
    vec out(p_.dim());
    for (int i = 0; i < p_.dim(); ++i) out[i] = y[offset + i];
    return out;
  }

  const method_table<P>* methods_;

  // The slot of the method named `method`: unknown names and methods that do not run on
  // P are refused, each in its own words.
  const method_slot<P>& slot(std::string_view method) const {
    find_method(method);  // throws for an unknown name
    for (const auto& s : *methods_)
      if (s.info->name == method) return s;
    not_applicable(method, name());
  }

 public:
  explicit problem_model(const method_table<P>& methods, P p = P{}) : p_(std::move(p)), methods_(&methods) {}

  // A problem type's name, or an instance's own where it has one (a scene file's).
  std::string_view name() const override {
    if constexpr (requires { p_.label(); })
      return p_.label();
    else
      return P::name;
  }
  std::string_view description() const override {
    if constexpr (requires { p_.summary(); })
      return p_.summary().empty() ? P::description : p_.summary();
    else
      return P::description;
  }
  int dim() const override { return p_.dim(); }
  std::string_view position_unit() const override { return P::position_unit; }

  std::vector<param_value> params() const override { return declared_params(p_); }
  void set(std::string_view param, double value) override {
    for (const auto& q : P::parameters())
      if (q.name == param) {
        p_.*q.member = value;
        return;
      }
    std::vector<std::string_view> known;
    for (const auto& q : P::parameters()) known.push_back(q.name);
    throw std::invalid_argument(
        fmt::format("unknown parameter '{}' for problem {} (known: {})", param, name(), fmt::join(known, ", ")));
  }
  std::string validate() const override { return stepbench::validate(p_); }
  double horizon() const override { return p_.horizon(); }
  bool has_closed_form() const override { return stepbench::has_closed_form<P>; }
  bool has_energy() const override { return stepbench::has_energy<P>; }
  bool has_jacobian() const override { return stepbench::has_jacobian<P>; }

  std::vector<double> exact(double t) const override {
    if constexpr (stepbench::has_closed_form<P>) return stacked(p_.exact(t));
    throw std::logic_error(fmt::format("problem {} has no closed form", name()));
  }
  double energy(std::span<const double> y) const override {
    if constexpr (stepbench::has_energy<P>) return p_.energy(unflatten(y, 0), unflatten(y, p_.dim()));
    return nan;
  }
  bool has_angular_momentum() const override { return stepbench::has_angular_momentum<P>; }
  double angular_momentum(std::span<const double> y) const override {
    if constexpr (stepbench::has_angular_momentum<P>)
      return p_.angular_momentum(unflatten(y, 0), unflatten(y, p_.dim()));
    return nan;
  }
  int observed_dim() const override {
    if constexpr (stepbench::has_observed_positions<P>) return p_.observed_dim();
    return p_.dim();
  }
  int body_dim() const override {
    if constexpr (stepbench::has_bodies<P>) return p_.body_dim();
    return observed_dim();
  }
  std::vector<double> observed(std::span<const double> y) const override {
    if constexpr (stepbench::has_observed_positions<P>) {
      const int n = p_.observed_dim();
      Eigen::VectorXd pos(n), vel(n);
      p_.observe(unflatten(y, 0), unflatten(y, p_.dim()), pos, vel);
      return stacked(pos, vel);
    } else {
      return {y.begin(), y.end()};
    }
  }
  double constraint_violation(std::span<const double> y) const override {
    if constexpr (stepbench::has_constraint_view<P>)
      return stepbench::constraint_violation(p_.particles(unflatten(y, 0), unflatten(y, p_.dim())));
    return nan;
  }
  double period() const override {
    if constexpr (stepbench::has_period<P>) return p_.period();
    return nan;
  }
  std::string_view contact_mode() const override {
    if constexpr (stepbench::has_contacts<P>) return p_.locate_contacts() ? "locate" : "end_of_step";
    return "none";
  }
  bool has_exact_contacts() const override { return stepbench::has_exact_contacts<P>; }
  exact_contact_list exact_contacts(double t_end) const override {
    if constexpr (stepbench::has_exact_contacts<P>) return p_.exact_contacts(t_end);
    throw std::logic_error(fmt::format("problem {} has no exact contacts", name()));
  }
  std::vector<double> initial() const override { return stacked(p_.initial()); }
  double fastest_frequency() const override { return stepbench::fastest_frequency(p_); }
  ode_system ode() const override {
    ode_system sys = make_ode_system(p_);
    if constexpr (stepbench::has_contacts<P>) {
      // The gap and the response for CVODE's root finding, on the problem's own functions.
      struct workspace {
        P p;
        vec x, v;
        Eigen::Index load(std::span<const double> y) {  // returns the dimension
          const auto d = static_cast<Eigen::Index>(y.size() / 2);
          x = Eigen::Map<const vec>(y.data(), d);
          v = Eigen::Map<const vec>(y.data() + d, d);
          return d;
        }
      };
      auto w = std::make_shared<workspace>(workspace{p_, p_.initial().x, p_.initial().v});
      sys.contact_gap = [w](double t, std::span<const double> y) {
        w->load(y);
        return w->p.contact_gap(t, w->x, w->v);
      };
      sys.resolve_contacts = [w](double t, std::span<double> y) {
        const Eigen::Index d = w->load(y);
        const contact_outcome c = w->p.resolve_contacts(t, w->x, w->v);
        Eigen::Map<vec>(y.data(), d) = w->x;
        Eigen::Map<vec>(y.data() + d, d) = w->v;
        return c.resolved;
      };
    }
    return sys;
  }

  // The table's methods, then the plugins' (registry/plugins.hpp): they run on every
  // problem, through our loops (registry/plugin_adapter.hpp), contacts and all.
  std::vector<method_info> methods() const override {
    std::vector<method_info> out;
    for (const auto& s : *methods_) out.push_back(*s.info);
    for (const auto& m : plugin_methods()) out.push_back(m.info);
    return out;
  }

  run_result run(std::string_view method, double param, double horizon, std::span<const double> times,
                 const run_limits& limits) const override {
    if (const plugin_method* m = find_plugin_method(method)) {
      const auto run_once = prepare_plugin(m->method, p_, param, horizon, times, limits);
      if (!plugin_isolation()) return run_prepared(run_once, param, horizon);
      run_result r = run_isolated([&] { return run_prepared(run_once, param, horizon); });
      r.param = param, r.horizon = horizon;  // also where the child crashed
      return r;
    }
    return slot(method).run(p_, param, horizon, times, limits);
  }

  std::function<double()> timed_run(std::string_view method, double param, double horizon,
                                    std::span<const double> times, const run_limits& limits) const override {
    if (const plugin_method* m = find_plugin_method(method))
      return timed_prepared(prepare_plugin(m->method, p_, param, horizon, times, limits));
    return slot(method).timed_run(p_, param, horizon, times, limits);
  }

  loop_result loop(std::string_view method, const loop_config& config) const override {
    const method_info& m = find_method(method);  // throws for an unknown name
    const bool offered = offered_as_ours(m.origin);
    if (!offered || m.kind != method_kind::fixed_step)
      throw std::invalid_argument(
          fmt::format("the game loop runs fixed-step integrators, ours and the plugins'; {} is {}", method,
                      offered ? std::string("adaptive") : fmt::format("a {} method", to_string(m.origin))));
    if (auto err = loop_config_error(config); !err.empty()) throw std::invalid_argument(err);
    // A plugin's fixed-step method steps the loop through its C function, as it steps
    // drive() (registry/plugin_adapter.hpp); in this process (--isolate is for runs).
    if (const plugin_method* pm = find_plugin_method(method))
      return simulate_loop(p_, plugin_fixed{{pm->method}}, config);
    const auto& s = slot(method);
    if (s.loop == nullptr)  // the position-based methods step particles, not the loop's states
      throw std::invalid_argument(
          fmt::format("the game loop runs force-based integrators; {} steps a constraint view", method));
    return s.loop(p_, config);
  }
};

// Puts a problem's table, filled group by group, into the registry's order of methods
// (all_methods()), whatever the order the groups were appended in.
template <class P>
void sort_by_registry_order(method_table<P>& table) {
  const auto& all = all_methods();
  auto rank = [&](const method_slot<P>& s) {
    return std::find_if(all.begin(), all.end(), [&](const method_info& m) { return m.name == s.info->name; }) -
           all.begin();
  };
  std::stable_sort(table.begin(), table.end(), [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
}

// One problem of the registry: its name and its problem_model's factory. Each problem's
// unit defines its entry; generated/registry/problem_entries.hpp lists them in order.
struct problem_entry {
  std::string_view name;
  std::unique_ptr<problem_instance> (*make)();
};

}  // namespace stepbench::registry_detail
